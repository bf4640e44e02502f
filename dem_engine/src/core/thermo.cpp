#include "core/thermo.h"

#include <cstdio>
#include <sstream>

#include "core/numbers.h"
#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {

namespace {
// A thermo keyword of the form c_ID, c_ID[i], f_ID, f_ID[i] or v_NAME; returns the value.
double reference_value(const Simulation& sim, const std::string& key) {
  const std::string body = key.substr(2);
  std::string id = body;
  int index = 0;
  const auto bracket = body.find('[');
  if (bracket != std::string::npos) {
    if (body.back() != ']') throw EngineError("bad thermo keyword '" + key + "'");
    id = body.substr(0, bracket);
    index = static_cast<int>(parse_int(body.substr(bracket + 1, body.size() - bracket - 2), key));
    if (index < 1) throw EngineError("thermo keyword '" + key + "': index must be >= 1");
  }
  if (key[0] == 'c') return sim.compute_value(id, index);
  if (key[0] == 'f') return sim.fix_value(id, index);
  return sim.variables.number(id, sim);
}

bool is_reference(const std::string& key) {
  return key.size() > 2 && key[1] == '_' && (key[0] == 'c' || key[0] == 'f' || key[0] == 'v');
}
}  // namespace

void Thermo::set_style(const std::vector<std::string>& args) {
  if (args.empty() || args[0] != "custom")
    throw EngineError("only 'thermo_style custom keyword ...' is supported");
  if (args.size() < 2) throw EngineError("thermo_style custom needs at least one keyword");
  static const char* known[] = {"step", "atoms", "ke", "time", "cpu", "dt", "elapsed", "elaplong"};
  std::vector<std::string> keys;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& k = args[i];
    bool ok = is_reference(k);
    for (const char* name : known) ok = ok || k == name;
    if (!ok) throw EngineError("unknown thermo keyword '" + k + "'");
    keys.push_back(k);
  }
  keywords = keys;
}

void Thermo::modify(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); i += 2) {
    if (i + 1 >= args.size()) throw EngineError("thermo_modify keyword '" + args[i] + "' needs a value");
    const std::string& key = args[i];
    const std::string& value = args[i + 1];
    if (key == "lost") {
      if (value != "ignore" && value != "error")
        throw EngineError("thermo_modify lost: expected ignore or error");
      lost_ignore = value == "ignore";
    } else if (key == "norm") {
      if (parse_yes_no(value, "norm")) throw EngineError("thermo_modify norm yes is not supported");
    } else if (key == "flush") {
      parse_yes_no(value, "flush");
    } else {
      throw EngineError("unknown thermo_modify keyword '" + key + "'");
    }
  }
}

std::string Thermo::column_name(const std::string& k) const {
  if (k == "step") return "Step";
  if (k == "atoms") return "Atoms";
  if (k == "ke") return "KinEng";
  if (k == "time") return "Time";
  if (k == "cpu") return "CPU";
  if (k == "dt") return "Dt";
  if (k == "elapsed") return "Elapsed";
  if (k == "elaplong") return "Elaplong";
  return k;
}

void Thermo::header(Simulation& sim) const {
  std::ostringstream os;
  for (std::size_t i = 0; i < keywords.size(); ++i)
    os << (i ? " " : "") << column_name(keywords[i]);
  sim.message(os.str());
}

void Thermo::row(Simulation& sim) const {
  std::ostringstream os;
  char buf[64];
  for (std::size_t i = 0; i < keywords.size(); ++i) {
    const std::string& k = keywords[i];
    if (k == "step" || k == "atoms" || k == "elaplong") {
      std::snprintf(buf, sizeof buf, "%ld", static_cast<long>(*sim.thermo_keyword(k)));
    } else {
      const double v = is_reference(k) ? reference_value(sim, k) : *sim.thermo_keyword(k);
      std::snprintf(buf, sizeof buf, "%.10g", v);
    }
    os << (i ? " " : "") << buf;
  }
  sim.message(os.str());
}

}  // namespace dem
