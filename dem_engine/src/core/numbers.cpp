#include "core/numbers.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "deck/errors.h"

namespace dem {

double parse_double(const std::string& text, const std::string& what) {
  if (!text.empty()) {
    errno = 0;
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (end && *end == '\0' && errno == 0 && std::isfinite(value)) return value;
  }
  throw EngineError("expected a number for " + what + ", got '" + text + "'");
}

long parse_int(const std::string& text, const std::string& what) {
  if (!text.empty()) {
    errno = 0;
    char* end = nullptr;
    const long value = std::strtol(text.c_str(), &end, 10);
    if (end && *end == '\0' && errno == 0) return value;
    // Accept integral values written as floats (e.g. 1e5) as LAMMPS does for step counts.
    const double d = std::strtod(text.c_str(), &end);
    if (end && *end == '\0' && std::isfinite(d) && d == std::floor(d) && std::fabs(d) < 9e15)
      return static_cast<long>(d);
  }
  throw EngineError("expected an integer for " + what + ", got '" + text + "'");
}

bool parse_yes_no(const std::string& text, const std::string& what) {
  // LIGGGHTS refuses on/off for these keywords (the contact model keywords, which take on/off,
  // are parsed elsewhere).
  if (text == "yes") return true;
  if (text == "no") return false;
  throw EngineError("expected yes or no for " + what + ", got '" + text + "'");
}

void require_args(const std::vector<std::string>& args, std::size_t n, const std::string& usage) {
  if (args.size() < n)
    throw EngineError("too few arguments (" + std::to_string(args.size()) + "); usage: " + usage);
}

}  // namespace dem
