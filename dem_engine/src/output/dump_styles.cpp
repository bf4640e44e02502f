#include <memory>

#include "core/numbers.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "io/dump.h"
#include "output/atom_dump.h"
#include "output/local_dump.h"

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

// The keywords every dump style shares; the styles handle theirs and pass the rest here.
void Dump::modify(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); i += 2) {
    const std::string& key = args[i];
    if ((key == "first" || key == "pad") && i + 1 < args.size()) {
      if (key == "first") {
        first_ = parse_yes_no(args[i + 1], "dump_modify first");
      } else {
        const long pad = parse_int(args[i + 1], "dump_modify pad");
        if (pad < 0 || pad > 30) throw EngineError("dump_modify pad must be in 0..30");
        pad_ = static_cast<int>(pad);
      }
      continue;
    }
    if (key != "every")
      throw EngineError("dump_modify: keyword '" + key + "' is not supported for dump " + id_ +
                        " (" + style_ + ")");
    if (i + 1 >= args.size()) throw EngineError("dump_modify every needs N");
    if (args[i + 1].rfind("v_", 0) == 0)
      throw EngineError("dump_modify every v_name is not supported (give a number of steps)");
    const long n = parse_int(args[i + 1], "dump_modify every");
    if (n < 1) throw EngineError("dump_modify every N must be >= 1");
    every_ = n;
  }
}

void register_dump_styles(DumpRegistry& registry) {
  registry["custom"] = [](Simulation& sim, const Command& c) {
    return std::make_unique<DumpCustom>(sim, c);
  };
  registry["custom/vtk"] = [](Simulation& sim, const Command& c) {
    return std::make_unique<DumpCustomVtk>(sim, c);
  };
  registry["local"] = [](Simulation& sim, const Command& c) {
    return std::make_unique<DumpLocal>(sim, c);
  };
}

const DumpRegistry& dump_registry() {
  static const DumpRegistry registry = [] {
    DumpRegistry r;
    register_dump_styles(r);
    return r;
  }();
  return registry;
}

}  // namespace dem
