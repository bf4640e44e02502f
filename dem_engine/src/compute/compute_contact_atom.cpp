#include "compute/compute_styles.h"
#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {
namespace {

// `compute ID group contact/atom`: per particle, the number of particles it touches (centre
// distance <= sum of radii); 0 for particles outside the group.
class ComputeContactAtom : public Compute {
 public:
  ComputeContactAtom(Simulation& sim, const Command& command) : Compute(sim, command) {
    if (!args_.empty()) throw EngineError("compute contact/atom takes no arguments");
  }
  bool peratom() const override { return true; }
  std::vector<double> peratom_values() const override {
    const Particles& p = sim_.atoms;
    const NeighborList& list = sim_.neighbor;
    const std::size_t n = p.size();
    std::vector<double> count(n, 0.0);
    if (n == 0) return count;
    if (list.first.size() != n + 1)
      throw EngineError("compute " + id() +
                        ": the neighbour list is not built (contact/atom needs a run first)");
    const std::uint32_t bit = group_bit();
    for (std::size_t i = 0; i < n; ++i)
      for (int k = list.first[i]; k < list.first[i + 1]; ++k) {
        const auto j = static_cast<std::size_t>(list.partner[static_cast<std::size_t>(k)]);
        const double reach = p.radius[i] + p.radius[j];
        if (norm2(sim_.domain.minimum_image(p.x[i] - p.x[j])) > reach * reach) continue;
        if (p.mask[i] & bit) count[i] += 1.0;
        if (p.mask[j] & bit) count[j] += 1.0;
      }
    return count;
  }
};

}  // namespace

std::unique_ptr<Compute> make_contact_atom(Simulation& sim, const Command& command) {
  return std::make_unique<ComputeContactAtom>(sim, command);
}

}  // namespace dem
