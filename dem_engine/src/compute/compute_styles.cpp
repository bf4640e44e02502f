#include "compute/compute_styles.h"

#include <map>
#include <string>

#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {

Compute::Compute(Simulation& sim, const Command& command) : sim_(sim) {
  if (command.args.size() < 3) throw EngineError("usage: compute ID group-ID style args...");
  id_ = command.args[0];
  group_bit_ = sim.groups.bit(command.args[1]);
  style_ = command.args[2];
  args_.assign(command.args.begin() + 3, command.args.end());
}

double Compute::scalar() const {
  throw EngineError("compute " + id_ + " (" + style_ + ") has no global scalar");
}

double Compute::vector(int index) const {
  throw EngineError("compute " + id_ + " (" + style_ + ") has no global vector element " +
                    std::to_string(index));
}

std::unique_ptr<Compute> make_compute(Simulation& sim, const Command& command) {
  using Factory = std::unique_ptr<Compute> (*)(Simulation&, const Command&);
  static const std::map<std::string, Factory> styles = {
      {"erotate/sphere", make_erotate_sphere},
      {"contact/atom", make_contact_atom},
      {"reduce", make_reduce},
      {"pair/gran/local", make_pair_gran_local},
  };
  const std::string style = command.args.size() > 2 ? command.args[2] : std::string();
  const auto it = styles.find(style);
  if (it == styles.end())
    throw EngineError("unknown compute style '" + style +
                      "' (supported: erotate/sphere, contact/atom, reduce, pair/gran/local)");
  return it->second(sim, command);
}

}  // namespace dem
