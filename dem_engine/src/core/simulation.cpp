#include "core/simulation.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "core/numbers.h"
#include "deck/errors.h"

namespace dem {

Simulation::Simulation(EngineOptions options)
    : options_(std::move(options)), wall_start_(std::chrono::steady_clock::now()) {
  input_ = std::make_unique<Input>(*this, variables);
  if (options_.log_file != "none") open_log(options_.log_file, false);
}

Simulation::~Simulation() = default;

void Simulation::run_deck(
    const std::string& path,
    const std::vector<std::pair<std::string, std::vector<std::string>>>& command_line_vars) {
  for (const auto& [name, values] : command_line_vars)
    variables.define_from_command_line(name, values);
  if (options_.echo_screen) input_->run_line("echo screen", SourceLocation{path, 0});
  input_->run_file(path);
}

void Simulation::message(const std::string& text) {
  std::cout << text << '\n';
  if (log_.is_open()) log_ << text << '\n';
}

void Simulation::warning(const std::string& text) {
  std::cerr << "WARNING: " << text << '\n';
  if (log_.is_open()) log_ << "WARNING: " << text << '\n';
}

void Simulation::open_log(const std::string& path, bool append) {
  if (log_.is_open()) log_.close();
  if (path == "none") return;
  log_.open(path, append ? std::ios::app : std::ios::trunc);
  if (!log_) throw EngineError("cannot open log file '" + path + "'");
}

Region& Simulation::region(const std::string& id) {
  auto it = regions.find(id);
  if (it == regions.end()) throw EngineError("unknown region '" + id + "'");
  return *it->second;
}

Fix* Simulation::find_fix(const std::string& id) const {
  for (const auto& f : fixes)
    if (f->id() == id) return f.get();
  return nullptr;
}

Fix& Simulation::fix(const std::string& id) const {
  Fix* f = find_fix(id);
  if (!f) throw EngineError("unknown fix '" + id + "'");
  return *f;
}

Compute& Simulation::compute(const std::string& id) const {
  for (const auto& c : computes)
    if (c->id() == id) return *c;
  throw EngineError("unknown compute '" + id + "'");
}

void Simulation::particles_changed() {
  neighbor.force_rebuild();
  changed_since_run_ = true;
}

double Simulation::max_radius() const {
  double r = 0.0;
  for (double ri : atoms.radius) r = std::max(r, ri);
  for (const auto& f : fixes) r = std::max(r, f->max_insert_radius());
  return r;
}

const ContactModel& Simulation::pair_model() const {
  if (!pair) throw EngineError("pair_style gran must be defined before walls and runs");
  return *pair;
}

ContactStep Simulation::wall_step() const {
  ContactStep step;
  step.options = pair_model().spec().options;
  step.dt = dt;
  step.update_history = !setting_up_;
  return step;
}

double Simulation::kinetic_energy(std::uint32_t bit) const {
  double ke = 0.0;
  for (std::size_t i = 0; i < atoms.size(); ++i)
    if (atoms.mask[i] & bit) ke += 0.5 * atoms.rmass[i] * norm2(atoms.v[i]);
  return ke;
}

double Simulation::cpu_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
}

std::optional<double> Simulation::thermo_keyword(const std::string& name) const {
  if (name == "step") return static_cast<double>(step);
  if (name == "atoms") return static_cast<double>(atoms.size());
  if (name == "time") return time;
  if (name == "dt") return dt;
  if (name == "ke") return kinetic_energy(1u);
  if (name == "cpu" || name == "elapsed") return cpu_seconds();
  if (name == "elaplong") return static_cast<double>(step - run_start_step);
  return std::nullopt;
}

namespace {
int dim_index(const std::string& d) {
  if (d == "x") return 0;
  if (d == "y") return 1;
  if (d == "z") return 2;
  throw EngineError("expected x, y or z, got '" + d + "'");
}
}  // namespace

double Simulation::group_function(const std::string& fn, const std::vector<std::string>& args) const {
  if (args.empty()) throw EngineError(fn + "() needs a group");
  const std::uint32_t bit = groups.bit(args[0]);
  // Optional trailing region argument, as in LAMMPS (e.g. count(all,box)).
  const Region* reg = nullptr;
  auto region_arg = [&](std::size_t pos) {
    if (args.size() > pos) {
      auto it = regions.find(args[pos]);
      if (it == regions.end()) throw EngineError(fn + "(): unknown region '" + args[pos] + "'");
      reg = it->second.get();
    }
  };
  auto selected = [&](std::size_t i) {
    return (atoms.mask[i] & bit) && (!reg || reg->inside(atoms.x[i]));
  };
  const std::size_t n = atoms.size();
  if (fn == "count" || fn == "mass" || fn == "ke") {
    region_arg(1);
    double s = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      if (selected(i))
        s += fn == "count" ? 1.0
                           : (fn == "mass" ? atoms.rmass[i] : 0.5 * atoms.rmass[i] * norm2(atoms.v[i]));
    return s;
  }
  if (fn == "xcm" || fn == "vcm" || fn == "fcm") {
    if (args.size() < 2) throw EngineError(fn + "() needs a group and a dimension");
    const int d = dim_index(args[1]);
    region_arg(2);
    double m = 0.0, s = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      if (selected(i)) {
        if (fn == "fcm") {
          s += atoms.f[i][d];  // total force on the group
          continue;
        }
        m += atoms.rmass[i];
        s += atoms.rmass[i] * (fn == "xcm" ? atoms.x[i][d] : atoms.v[i][d]);
      }
    if (fn == "fcm") return s;
    return m > 0.0 ? s / m : 0.0;
  }
  if (fn == "bound") {
    if (args.size() < 2) throw EngineError("bound() needs a group and xmin|xmax|ymin|...");
    const std::string& which = args[1];
    if (which.size() != 4 || (which.substr(1) != "min" && which.substr(1) != "max"))
      throw EngineError("bound(): expected xmin, xmax, ymin, ymax, zmin or zmax, got '" + which + "'");
    const int d = dim_index(which.substr(0, 1));
    const bool is_max = which.substr(1) == "max";
    region_arg(2);
    double b = is_max ? -1e300 : 1e300;
    for (std::size_t i = 0; i < n; ++i)
      if (selected(i)) b = is_max ? std::max(b, atoms.x[i][d]) : std::min(b, atoms.x[i][d]);
    return b;
  }
  throw EngineError("unknown group function '" + fn + "'");
}

double Simulation::compute_value(const std::string& id, int index) const {
  const Compute& c = compute(id);
  return index == 0 ? c.scalar() : c.vector(index);
}

double Simulation::fix_value(const std::string& id, int index) const {
  const Fix& f = fix(id);
  return index == 0 ? f.scalar() : f.vector(index);
}

}  // namespace dem
