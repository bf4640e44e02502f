// The command table: every deck command the input reader does not handle itself.
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "core/numbers.h"
#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {
namespace {

using Handler = std::function<void(Simulation&, const std::vector<std::string>&)>;

void expect_exact(const std::vector<std::string>& args, std::initializer_list<const char*> words,
                  const std::string& command) {
  std::vector<std::string> want(words.begin(), words.end());
  if (args != want) {
    std::string text;
    for (const auto& w : want) text += " " + w;
    throw EngineError("only '" + command + text + "' is supported");
  }
}

void cmd_boundary(Simulation& s, const std::vector<std::string>& a) {
  if (a.size() != 3) throw EngineError("usage: boundary x y z (each p, f, m or s)");
  for (int k = 0; k < 3; ++k) {
    const std::string& b = a[k];
    // LAMMPS allows two letters (lower and upper face); both must be the same here.
    if (b.empty() || b.size() > 2 || (b.size() == 2 && b[0] != b[1]) ||
        std::string("pfms").find(b[0]) == std::string::npos)
      throw EngineError("unsupported boundary '" + b + "' (use p, f, m or s)");
    s.domain.boundary[k] = b[0];
  }
}

void cmd_create_box(Simulation& s, const std::vector<std::string>& a) {
  require_args(a, 2, "create_box N region-ID");
  if (s.domain.defined) throw EngineError("the box is already defined");
  const long n = parse_int(a[0], "number of atom types");
  if (n < 1 || n > 64) throw EngineError("number of atom types must be in 1..64");
  const Region& r = s.region(a[1]);
  s.domain.lo = r.extent_lo();
  s.domain.hi = r.extent_hi();
  for (int k = 0; k < 3; ++k)
    if (std::fabs(s.domain.lo[k]) > 1e20 || std::fabs(s.domain.hi[k]) > 1e20)
      throw EngineError("create_box region must be bounded");
  s.domain.defined = true;
  s.ntypes = static_cast<int>(n);
}

void cmd_neighbor(Simulation& s, const std::vector<std::string>& a) {
  if (a.size() != 2 || a[1] != "bin") throw EngineError("usage: neighbor SKIN bin");
  s.neighbor.skin = parse_double(a[0], "neighbor skin");
  if (s.neighbor.skin <= 0) throw EngineError("neighbor skin must be > 0");
}

void cmd_neigh_modify(Simulation& s, const std::vector<std::string>& a) {
  for (std::size_t i = 0; i < a.size(); i += 2) {
    if (i + 1 >= a.size()) throw EngineError("neigh_modify keyword '" + a[i] + "' needs a value");
    if (a[i] == "delay") s.neighbor.delay = static_cast<int>(parse_int(a[i + 1], "delay"));
    else if (a[i] == "every") s.neighbor.every = static_cast<int>(parse_int(a[i + 1], "every"));
    else if (a[i] == "check") s.neighbor.check = parse_yes_no(a[i + 1], "check");
    else throw EngineError("unknown neigh_modify keyword '" + a[i] + "'");
  }
}

void cmd_pair_style(Simulation& s, const std::vector<std::string>& a) {
  if (a.empty() || a[0] != "gran")
    throw EngineError("only pair_style gran is supported");
  ModelSpec spec;
  parse_pair_model(a, 1, spec);
  s.pair = make_contact_model(spec);
}

void cmd_pair_coeff(Simulation& s, const std::vector<std::string>& a) {
  if (!s.pair) throw EngineError("pair_coeff before pair_style");
  expect_exact(a, {"*", "*"}, "pair_coeff");
}

void cmd_create_atoms(Simulation& s, const std::vector<std::string>& a) {
  if (!s.domain.defined) throw EngineError("create_atoms before create_box");
  require_args(a, 5, "create_atoms TYPE single X Y Z [units box]");
  const long type = parse_int(a[0], "atom type");
  if (type < 1 || type > s.ntypes) throw EngineError("atom type out of range");
  if (a[1] != "single") throw EngineError("only 'create_atoms TYPE single X Y Z' is supported");
  const Vec3 p{parse_double(a[2], "x"), parse_double(a[3], "y"), parse_double(a[4], "z")};
  for (std::size_t i = 5; i < a.size(); i += 2) {
    if (a[i] != "units" || i + 1 >= a.size() || a[i + 1] != "box")
      throw EngineError("unsupported create_atoms keyword '" + a[i] + "' (only 'units box')");
  }
  // LIGGGHTS granular defaults: diameter 1, density 1 until `set` changes them.
  s.atoms.add(s.atoms.next_tag(), static_cast<int>(type), 1u, p, 0.5, 1.0);
  s.particles_changed();
}

void cmd_set(Simulation& s, const std::vector<std::string>& a) {
  require_args(a, 4, "set atom|group|region ID keyword value ...");
  const std::string& what = a[0];
  std::function<bool(std::size_t)> selected;
  if (what == "atom") {
    const long id = parse_int(a[1], "atom id");
    selected = [&s, id](std::size_t i) { return s.atoms.tag[i] == id; };
  } else if (what == "group") {
    const std::uint32_t bit = s.groups.bit(a[1]);
    selected = [&s, bit](std::size_t i) { return (s.atoms.mask[i] & bit) != 0; };
  } else if (what == "region") {
    const Region* r = &s.region(a[1]);
    selected = [&s, r](std::size_t i) { return r->inside(s.atoms.x[i]); };
  } else {
    throw EngineError("set: expected atom, group or region, got '" + what + "'");
  }
  for (std::size_t k = 2; k < a.size(); k += 2) {
    if (k + 1 >= a.size()) throw EngineError("set keyword '" + a[k] + "' needs a value");
    const std::string& key = a[k];
    const double v = parse_double(a[k + 1], "set " + key);
    for (std::size_t i = 0; i < s.atoms.size(); ++i) {
      if (!selected(i)) continue;
      if (key == "diameter") {
        if (v <= 0) throw EngineError("diameter must be > 0");
        s.atoms.set_radius(i, 0.5 * v);
      } else if (key == "density") {
        if (v <= 0) throw EngineError("density must be > 0");
        s.atoms.set_density(i, v);
      } else if (key == "type") {
        if (v < 1 || v > s.ntypes) throw EngineError("atom type out of range");
        s.atoms.type[i] = static_cast<int>(v);
      } else if (key == "vx" || key == "vy" || key == "vz") {
        s.atoms.v[i][key[1] - 'x'] = v;
      } else if (key == "omegax" || key == "omegay" || key == "omegaz") {
        s.atoms.omega[i][key[5] - 'x'] = v;
      } else if (key == "x" || key == "y" || key == "z") {
        s.atoms.x[i][key[0] - 'x'] = v;
      } else {
        throw EngineError("unsupported set keyword '" + key + "'");
      }
    }
  }
  s.particles_changed();
}

void cmd_group(Simulation& s, const std::vector<std::string>& a) {
  require_args(a, 2, "group ID region|type|id args");
  if (a[0] == "all") throw EngineError("group 'all' cannot be redefined");
  const std::string& style = a[1];
  if (style == "delete") throw EngineError("group delete is not supported");
  const std::uint32_t bit = s.groups.find_or_create(a[0]);
  std::vector<char> add(s.atoms.size(), 0);
  if (style == "region") {
    require_args(a, 3, "group ID region REGION-ID");
    const Region& r = s.region(a[2]);
    for (std::size_t i = 0; i < s.atoms.size(); ++i) add[i] = r.inside(s.atoms.x[i]);
  } else if (style == "type" || style == "id") {
    require_args(a, 3, "group ID " + style + " values...");
    for (std::size_t k = 2; k < a.size(); ++k) {
      long lo, hi;
      const auto colon = a[k].find(':');
      if (colon == std::string::npos) {
        lo = hi = parse_int(a[k], "group " + style);
      } else {
        lo = parse_int(a[k].substr(0, colon), "group " + style + " range");
        hi = parse_int(a[k].substr(colon + 1), "group " + style + " range");
      }
      for (std::size_t i = 0; i < s.atoms.size(); ++i) {
        const long v = style == "type" ? s.atoms.type[i] : static_cast<long>(s.atoms.tag[i]);
        if (v >= lo && v <= hi) add[i] = 1;
      }
    }
  } else {
    throw EngineError("unsupported group style '" + style + "' (region, type, id)");
  }
  for (std::size_t i = 0; i < s.atoms.size(); ++i)
    if (add[i]) s.atoms.mask[i] |= bit;
}

void cmd_velocity(Simulation& s, const std::vector<std::string>& a) {
  require_args(a, 5, "velocity GROUP set VX VY VZ [sum no] [units box]");
  const std::uint32_t bit = s.groups.bit(a[0]);
  if (a[1] != "set") throw EngineError("only 'velocity GROUP set VX VY VZ' is supported");
  bool sum = false;
  for (std::size_t k = 5; k < a.size(); k += 2) {
    if (k + 1 >= a.size()) throw EngineError("velocity keyword '" + a[k] + "' needs a value");
    if (a[k] == "sum") sum = parse_yes_no(a[k + 1], "sum");
    else if (a[k] == "units" && a[k + 1] == "box") continue;
    else throw EngineError("unsupported velocity keyword '" + a[k] + "'");
  }
  for (int d = 0; d < 3; ++d) {
    if (a[2 + d] == "NULL") continue;
    const double v = parse_double(a[2 + d], "velocity component");
    for (std::size_t i = 0; i < s.atoms.size(); ++i)
      if (s.atoms.mask[i] & bit) s.atoms.v[i][d] = sum ? s.atoms.v[i][d] + v : v;
  }
}

void cmd_delete_atoms(Simulation& s, const std::vector<std::string>& a) {
  require_args(a, 2, "delete_atoms region REGION-ID | group GROUP-ID");
  std::vector<char> del(s.atoms.size(), 0);
  if (a[0] == "region") {
    const Region& r = s.region(a[1]);
    for (std::size_t i = 0; i < s.atoms.size(); ++i) del[i] = r.inside(s.atoms.x[i]);
  } else if (a[0] == "group") {
    const std::uint32_t bit = s.groups.bit(a[1]);
    for (std::size_t i = 0; i < s.atoms.size(); ++i) del[i] = (s.atoms.mask[i] & bit) != 0;
  } else {
    throw EngineError("delete_atoms: expected region or group, got '" + a[0] + "'");
  }
  bool compress = true;  // LAMMPS default: the remaining particles get the ids 1..N
  for (std::size_t k = 2; k < a.size(); k += 2) {
    if (a[k] != "compress") throw EngineError("unsupported delete_atoms keyword '" + a[k] + "'");
    if (k + 1 >= a.size() || (a[k + 1] != "yes" && a[k + 1] != "no"))
      throw EngineError("delete_atoms compress expects yes or no");
    compress = a[k + 1] == "yes";
  }
  s.atoms.remove(del);
  if (compress) s.neighbor.retag(s.atoms.renumber_tags());
  s.particles_changed();
}

void cmd_fix(Simulation& s, const std::vector<std::string>& a, const Command& command) {
  require_args(a, 3, "fix ID group-ID style args...");
  const auto& registry = fix_registry();
  auto it = registry.find(a[2]);
  if (it == registry.end()) throw EngineError("unknown fix style '" + a[2] + "'");
  auto same_id = std::find_if(s.fixes.begin(), s.fixes.end(),
                              [&](const auto& f) { return f->id() == a[0]; });
  if (same_id != s.fixes.end()) {
    // LAMMPS semantics: a fix with an existing ID replaces it in place, if of the same style.
    const std::string& old_style = (*same_id)->style();
    if (old_style != a[2])
      throw EngineError("fix " + a[0] + " exists with style " + old_style +
                        "; replacing a fix by one of another style (" + a[2] +
                        ") is an error in LIGGGHTS 3.8: unfix it first");
    if (old_style == "wall/gran")
      throw EngineError("fix " + a[0] + " (wall/gran) is defined again without unfix, which "
                        "LIGGGHTS 3.8 does not support (it crashes): unfix it first");
    // The old fix's properties go first: the new one registers its own under the same ID.
    s.properties.remove_owned_by(a[0]);
    *same_id = it->second(s, command);
    return;
  }
  s.fixes.push_back(it->second(s, command));
}

void cmd_unfix(Simulation& s, const std::vector<std::string>& a) {
  require_args(a, 1, "unfix ID");
  auto it = std::find_if(s.fixes.begin(), s.fixes.end(),
                         [&](const auto& f) { return f->id() == a[0]; });
  if (it == s.fixes.end()) throw EngineError("unfix: unknown fix '" + a[0] + "'");
  s.properties.remove_owned_by(a[0]);
  s.fixes.erase(it);
}

void cmd_fix_modify(Simulation& s, const std::vector<std::string>& a) {
  require_args(a, 2, "fix_modify ID keyword value ...");
  s.fix(a[0]).modify(std::vector<std::string>(a.begin() + 1, a.end()));
}

void cmd_compute(Simulation& s, const Command& command) {
  require_args(command.args, 3, "compute ID group-ID style args...");
  for (const auto& c : s.computes)
    if (c->id() == command.args[0]) throw EngineError("compute ID '" + c->id() + "' already exists");
  s.computes.push_back(make_compute(s, command));
}

void cmd_dump(Simulation& s, const Command& command) {
  const auto& a = command.args;
  require_args(a, 5, "dump ID group-ID style N file args...");
  const auto& registry = dump_registry();
  auto it = registry.find(a[2]);
  if (it == registry.end()) throw EngineError("unknown dump style '" + a[2] + "'");
  for (const auto& d : s.dumps)
    if (d->id() == a[0]) throw EngineError("dump ID '" + a[0] + "' already exists");
  s.dumps.push_back(it->second(s, command));
}

void cmd_undump(Simulation& s, const std::vector<std::string>& a) {
  require_args(a, 1, "undump ID");
  auto it = std::find_if(s.dumps.begin(), s.dumps.end(),
                         [&](const auto& d) { return d->id() == a[0]; });
  if (it == s.dumps.end()) throw EngineError("undump: unknown dump '" + a[0] + "'");
  s.dumps.erase(it);
}

void cmd_dump_modify(Simulation& s, const std::vector<std::string>& a) {
  require_args(a, 2, "dump_modify ID keyword value ...");
  for (auto& d : s.dumps)
    if (d->id() == a[0]) {
      d->modify(std::vector<std::string>(a.begin() + 1, a.end()));
      return;
    }
  throw EngineError("dump_modify: unknown dump '" + a[0] + "'");
}

}  // namespace

void Simulation::execute(const Command& command) {
  const auto& a = command.args;
  const std::string& name = command.name;
  static const std::map<std::string, Handler> table = {
      {"units", [](Simulation&, const std::vector<std::string>& x) { expect_exact(x, {"si"}, "units"); }},
      {"atom_style",
       [](Simulation&, const std::vector<std::string>& x) {
         expect_exact(x, {"granular"}, "atom_style");
       }},
      {"atom_modify",
       [](Simulation&, const std::vector<std::string>& x) {
         // Only the id map choice, which does not change results here.
         if (x.size() != 2 || x[0] != "map" || (x[1] != "array" && x[1] != "hash"))
           throw EngineError("only 'atom_modify map array|hash' is supported");
       }},
      {"newton",
       [](Simulation&, const std::vector<std::string>& x) {
         expect_exact(x, {"off"}, "newton");
       }},
      {"communicate",
       [](Simulation&, const std::vector<std::string>& x) {
         expect_exact(x, {"single", "vel", "yes"}, "communicate");
       }},
      {"processors",
       // The MPI domain decomposition; this engine runs the same model in one process.
       [](Simulation&, const std::vector<std::string>& x) {
         if (x.size() < 3) throw EngineError("usage: processors Px Py Pz");
         for (int k = 0; k < 3; ++k)
           if (x[k] != "*" && parse_int(x[k], "processors count") < 1)
             throw EngineError("processors counts must be * or >= 1");
         if (x.size() > 3)
           throw EngineError("processors keyword '" + x[3] + "' is not supported by this engine");
       }},
      {"soft_particles",
       [](Simulation& s, const std::vector<std::string>& x) {
         if (x.size() != 1 || (x[0] != "yes" && x[0] != "no"))
           throw EngineError("soft_particles expects 'yes' or 'no'");
         s.soft_particles = x[0] == "yes";
       }},
      {"hard_particles",
       [](Simulation& s, const std::vector<std::string>& x) {
         if (x.size() != 1 || (x[0] != "yes" && x[0] != "no"))
           throw EngineError("hard_particles expects 'yes' or 'no'");
         s.hard_particles = x[0] == "yes";
       }},
      {"boundary", cmd_boundary},
      {"region",
       [](Simulation& s, const std::vector<std::string>& x) {
         require_args(x, 2, "region ID style args...");
         if (s.regions.count(x[0])) throw EngineError("region '" + x[0] + "' already exists");
         s.regions[x[0]] = make_region(std::vector<std::string>(x.begin() + 1, x.end()),
                                       s.domain.lo, s.domain.hi, s.domain.defined);
       }},
      {"create_box", cmd_create_box},
      {"neighbor", cmd_neighbor},
      {"neigh_modify", cmd_neigh_modify},
      {"timestep",
       [](Simulation& s, const std::vector<std::string>& x) {
         require_args(x, 1, "timestep DT");
         s.dt = parse_double(x[0], "timestep");
         if (s.dt <= 0) throw EngineError("timestep must be > 0");
       }},
      {"pair_style", cmd_pair_style},
      {"pair_coeff", cmd_pair_coeff},
      {"create_atoms", cmd_create_atoms},
      {"set", cmd_set},
      {"group", cmd_group},
      {"velocity", cmd_velocity},
      {"delete_atoms", cmd_delete_atoms},
      {"unfix", cmd_unfix},
      {"fix_modify", cmd_fix_modify},
      {"uncompute",
       [](Simulation& s, const std::vector<std::string>& x) {
         require_args(x, 1, "uncompute ID");
         auto it = std::find_if(s.computes.begin(), s.computes.end(),
                                [&](const auto& c) { return c->id() == x[0]; });
         if (it == s.computes.end()) throw EngineError("uncompute: unknown compute '" + x[0] + "'");
         s.computes.erase(it);
       }},
      {"undump", cmd_undump},
      {"dump_modify", cmd_dump_modify},
      {"thermo",
       [](Simulation& s, const std::vector<std::string>& x) {
         require_args(x, 1, "thermo N");
         s.thermo.every = parse_int(x[0], "thermo N");
         if (s.thermo.every < 0) throw EngineError("thermo N must be >= 0");
       }},
      {"thermo_style", [](Simulation& s, const std::vector<std::string>& x) { s.thermo.set_style(x); }},
      {"thermo_modify", [](Simulation& s, const std::vector<std::string>& x) { s.thermo.modify(x); }},
  };
  if (name == "fix") return cmd_fix(*this, a, command);
  if (name == "compute") return cmd_compute(*this, command);
  if (name == "dump") return cmd_dump(*this, command);
  if (name == "run") return run(command);
  auto it = table.find(name);
  if (it == table.end()) throw EngineError("unknown command");
  it->second(*this, a);
}

}  // namespace dem
