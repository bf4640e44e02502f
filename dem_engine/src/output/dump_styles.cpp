#include "core/simulation.h"
#include "core/numbers.h"
#include "io/dump.h"

namespace dem {

Dump::Dump(Simulation& sim, const Command& command) : sim_(sim) {
  require_args(command.args, 5, "dump ID group-ID style N file args");
  id_ = command.args[0];
  group_bit_ = sim.groups.bit(command.args[1]);
  style_ = command.args[2];
  every_ = parse_int(command.args[3], "dump N");
  file_ = command.args[4];
  args_.assign(command.args.begin() + 5, command.args.end());
}

void Dump::modify(const std::vector<std::string>& args) {
  throw EngineError("dump_modify: unsupported keyword '" + (args.empty() ? "" : args[0]) + "'");
}

void register_dump_styles(DumpRegistry&) {}

const DumpRegistry& dump_registry() {
  static const DumpRegistry registry = [] {
    DumpRegistry r;
    register_dump_styles(r);
    return r;
  }();
  return registry;
}

}  // namespace dem
