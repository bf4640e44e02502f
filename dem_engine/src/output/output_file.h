#pragma once
#include <string>

namespace dem {

// Replaces the first '*' of a dump file name by the step number, zero-padded to `pad` digits
// (dump_modify pad); names without '*' are returned unchanged.
std::string expand_step_pattern(const std::string& pattern, long step, int pad);

// Writes `content` to a hidden temporary file next to `path` and renames it over `path`, so a
// reader never sees a partly written file. Throws EngineError naming the path on failure.
void write_file_atomically(const std::string& path, const std::string& content);

// printf-style formatting of one number into a std::string ("%g", "%.10g", "%ld").
std::string format_number(const char* format, double value);
std::string format_integer(long long value);

}  // namespace dem
