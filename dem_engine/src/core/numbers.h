#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace dem {

// Strict conversion of deck words; the error names `what` and the offending text.
double parse_double(const std::string& text, const std::string& what);
long parse_int(const std::string& text, const std::string& what);
bool parse_yes_no(const std::string& text, const std::string& what);
// Throws EngineError unless args.size() >= n.
void require_args(const std::vector<std::string>& args, std::size_t n, const std::string& usage);

}  // namespace dem
