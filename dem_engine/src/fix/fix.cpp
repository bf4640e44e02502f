#include "fix/fix.h"

#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {

Fix::Fix(Simulation& sim, const Command& command) : sim_(sim), where_(command.where) {
  if (command.args.size() < 3) throw EngineError("usage: fix ID group-ID style args...");
  id_ = command.args[0];
  group_bit_ = sim.groups.bit(command.args[1]);
  style_ = command.args[2];
  args_.assign(command.args.begin() + 3, command.args.end());
}

double Fix::scalar() const { throw EngineError("fix " + id_ + " (" + style_ + ") has no scalar"); }

double Fix::vector(int index) const {
  throw EngineError("fix " + id_ + " (" + style_ + ") has no vector element " +
                    std::to_string(index));
}

void Fix::modify(const std::vector<std::string>& args) {
  throw EngineError("fix_modify: fix " + id_ + " (" + style_ + ") has no keyword '" +
                    (args.empty() ? std::string() : args[0]) + "'");
}

const FixRegistry& fix_registry() {
  static const FixRegistry registry = [] {
    FixRegistry r;
    register_core_fix_styles(r);
    register_mesh_fix_styles(r);
    register_insert_fix_styles(r);
    register_output_fix_styles(r);
    return r;
  }();
  return registry;
}

}  // namespace dem
