#include <memory>

#include "fix/fix.h"
#include "insert/insert_fix.h"
#include "insert/particle_template_fix.h"

namespace dem {

void register_insert_fix_styles(FixRegistry& registry) {
  registry["particletemplate/sphere"] = [](Simulation& sim, const Command& c) {
    return std::make_unique<ParticleTemplateFix>(sim, c);
  };
  for (const char* style : {"particledistribution/discrete",
                            "particledistribution/discrete/massbased",
                            "particledistribution/discrete/numberbased"})
    registry[style] = [](Simulation& sim, const Command& c) {
      return std::make_unique<ParticleDistributionFix>(sim, c);
    };
  registry["insert/pack"] = [](Simulation& sim, const Command& c) {
    return std::make_unique<InsertPackFix>(sim, c);
  };
  registry["insert/rate/region"] = [](Simulation& sim, const Command& c) {
    return std::make_unique<InsertRateRegionFix>(sim, c);
  };
}

}  // namespace dem
