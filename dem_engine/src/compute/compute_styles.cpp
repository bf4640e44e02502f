#include "core/compute.h"
#include "core/simulation.h"

namespace dem {

Compute::Compute(Simulation& sim, const Command& command) : sim_(sim) {
  if (command.args.size() < 3) throw EngineError("usage: compute ID group-ID style args...");
  id_ = command.args[0];
  group_bit_ = sim.groups.bit(command.args[1]);
  style_ = command.args[2];
  args_.assign(command.args.begin() + 3, command.args.end());
}

double Compute::scalar() const { throw EngineError("compute " + id_ + " has no scalar"); }
double Compute::vector(int index) const {
  throw EngineError("compute " + id_ + " has no vector element " + std::to_string(index));
}

std::unique_ptr<Compute> make_compute(Simulation&, const Command& command) {
  throw EngineError("unknown compute style '" + (command.args.size() > 2 ? command.args[2] : "") +
                    "'");
}

}  // namespace dem
