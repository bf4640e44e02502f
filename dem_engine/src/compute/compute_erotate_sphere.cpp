#include "compute/compute_styles.h"
#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {
namespace {

// `compute ID group erotate/sphere`: rotational kinetic energy sum(1/2 I w^2) of the group's
// spheres, I = 2/5 m r^2 (J).
class ComputeErotateSphere : public Compute {
 public:
  ComputeErotateSphere(Simulation& sim, const Command& command) : Compute(sim, command) {
    if (!args_.empty()) throw EngineError("compute erotate/sphere takes no arguments");
  }
  double scalar() const override {
    const Particles& p = sim_.atoms;
    double sum = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.mask[i] & group_bit())
        sum += p.rmass[i] * p.radius[i] * p.radius[i] * norm2(p.omega[i]);
    return 0.5 * 0.4 * sum;
  }
};

}  // namespace

std::unique_ptr<Compute> make_erotate_sphere(Simulation& sim, const Command& command) {
  return std::make_unique<ComputeErotateSphere>(sim, command);
}

}  // namespace dem
