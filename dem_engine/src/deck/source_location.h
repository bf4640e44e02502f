#pragma once
#include <string>

namespace dem {

// Where a command came from: deck file and 1-based line of its first physical line.
struct SourceLocation {
  std::string file;
  int line = 0;
};

}  // namespace dem
