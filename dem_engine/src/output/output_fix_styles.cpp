#include <memory>

#include "fix/fix.h"
#include "output/output_fixes.h"

namespace dem {

void register_output_fix_styles(FixRegistry& registry) {
  registry["print"] = [](Simulation& sim, const Command& c) {
    return std::make_unique<FixPrint>(sim, c);
  };
  registry["ave/time"] = [](Simulation& sim, const Command& c) {
    return std::make_unique<FixAveTime>(sim, c);
  };
}

}  // namespace dem
