#include "output/output_file.h"

#include <cstdio>
#include <fstream>

#include "deck/errors.h"

namespace dem {

std::string expand_step_pattern(const std::string& pattern, long step, int pad) {
  const std::size_t star = pattern.find('*');
  if (star == std::string::npos) return pattern;
  char digits[32];
  std::snprintf(digits, sizeof digits, "%0*ld", pad, step);
  return pattern.substr(0, star) + digits + pattern.substr(star + 1);
}

void write_file_atomically(const std::string& path, const std::string& content) {
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
  const std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::string temporary = dir + "." + base + ".part";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw EngineError("cannot open '" + temporary + "' for writing");
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out) throw EngineError("cannot write '" + temporary + "' (disk full?)");
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::remove(temporary.c_str());
    throw EngineError("cannot rename '" + temporary + "' to '" + path + "'");
  }
}

std::string format_number(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

std::string format_integer(long long value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%lld", value);
  return buffer;
}

}  // namespace dem
