#pragma once
#include <string>
#include <vector>

#include "deck/source_location.h"

namespace dem {

// One deck command after continuation joining, comment removal, variable substitution
// and word splitting (quotes removed from quoted words).
struct Command {
  SourceLocation where;
  std::string name;
  std::vector<std::string> args;
};

}  // namespace dem
