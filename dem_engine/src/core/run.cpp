// `run`: set-up, the velocity-Verlet step loop and the numerical safety checks.
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "core/numbers.h"
#include "core/threads.h"
#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {

namespace {

std::string format_g(double v, int precision = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", precision, v);
  return buf;
}

// Prints progress to the terminal (stderr), never to the log file that readers parse.
class Progress {
 public:
  Progress(bool enabled, long n_steps) : enabled_(enabled), n_(n_steps) {
    tty_ = isatty(STDERR_FILENO) != 0;
    interval_ = tty_ ? 1.0 : 30.0;
    start_ = last_ = std::chrono::steady_clock::now();
  }
  void update(long done, std::size_t particles) {
    if (!enabled_ || n_ < 1000 || done % 100 != 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - last_).count() < interval_) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = done > 0 ? static_cast<double>(done) * particles / elapsed : 0.0;
    const double eta = done > 0 ? elapsed * (n_ - done) / done : 0.0;
    std::ostringstream os;
    os << "run " << format_g(100.0 * done / n_, 3) << "% | " << particles << " particles | "
       << format_g(rate, 3) << " particle-steps/s | ETA " << format_g(eta, 3) << " s";
    if (tty_) std::cerr << '\r' << os.str() << "   " << std::flush;
    else std::cerr << os.str() << '\n';
  }
  void finish() {
    if (enabled_ && tty_ && n_ >= 1000) std::cerr << '\n';
  }

 private:
  bool enabled_, tty_ = false;
  long n_;
  double interval_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace

void Simulation::compute_forces() {
  pair_forces();
  force_hooks(false);
}

void Simulation::force_hooks(bool final) {
  std::vector<HookWork> batch;  // hooks with a share, not yet run
  auto flush = [&]() {
    if (batch.empty()) return;
    for (HookWork& w : batch)
      if (w.before) w.before();
    neighbor.partition().for_each(atoms.size(), [&](std::size_t begin, std::size_t end) {
      for (HookWork& w : batch) w.share(begin, end);
    });
    for (HookWork& w : batch)
      if (w.after) w.after();
    batch.clear();
  };
  for (int pass = 0; pass < (final ? 2 : 1); ++pass)
    for (auto& f : fixes) {
      HookWork w = pass == 0 ? f->post_force_work() : f->final_integrate_work();
      if (w.share) {
        batch.push_back(std::move(w));
      } else if (w.before || w.after) {
        flush();
        if (w.before) w.before();
        if (w.after) w.after();
      }
    }
  flush();
}

void Simulation::pair_forces() {
  const std::size_t n = atoms.size();
  if (!pair || n == 0) {
    std::fill(atoms.f.begin(), atoms.f.end(), Vec3{});
    std::fill(atoms.torque.begin(), atoms.torque.end(), Vec3{});
  } else {  // the pair forces overwrite f and torque
    std::uint32_t freeze_bit = 0;
    for (const auto& f : fixes)
      if (f->style() == "freeze") {
        freeze_bit = f->group_bit();
        break;
      }
    PairForceArgs args{atoms,        neighbor,   material,     domain, dt,
                       !setting_up_, freeze_bit, pair_scratch_};
    pair->pair_forces(args);
    if (args.max_overlap_ratio > DeepOverlaps::kRatio)
      note_deep_overlap(args.max_overlap_ratio, args.max_overlap_tag, "a neighbour");
  }
}

void Simulation::note_deep_overlap(double ratio, long tag, const std::string& partner) {
  // A run's initial force evaluation repeats the previous run's last step.
  if (setting_up_ || !deep_overlaps_.record(step, ratio, tag, partner)) return;
  std::ostringstream os;
  os << "step " << step << ": particle " << tag << " overlaps " << partner << " by "
     << format_g(100.0 * ratio, 3)
     << " % of its radius (pinched between walls, or a time step too large for the stiffness); "
        "the run goes on, as in LIGGGHTS";
  warning(os.str());
}

void Simulation::check_health() const {
  const std::size_t n = atoms.size();
  double rmin = 1e300;
  for (double r : atoms.radius) rmin = std::min(rmin, r);
  // A particle moving more than half its radius in one step cannot be resolved.
  const double vmax = 0.5 * rmin / dt;
  // Each thread checks its own share (one thread reading every position and velocity would
  // pull them into its cache, and the other threads' next kick would wait to take them back);
  // the first particle at fault in index order is reported, as a serial scan would.
  const Vec3* const x = atoms.x.data();
  const Vec3* const v = atoms.v.data();
  auto finite = [&](std::size_t i) {
    return std::isfinite(x[i].x) && std::isfinite(x[i].y) && std::isfinite(x[i].z) &&
           std::isfinite(v[i].x) && std::isfinite(v[i].y) && std::isfinite(v[i].z);
  };
  std::vector<std::size_t> first_bad(static_cast<std::size_t>(omp_get_max_threads()), n);
  neighbor.partition().for_each(n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      if (!finite(i) || norm(v[i]) > vmax) {
        first_bad[static_cast<std::size_t>(omp_get_thread_num())] = i;
        return;
      }
  });
  const std::size_t i = *std::min_element(first_bad.begin(), first_bad.end());
  if (i == n) return;
  const std::string who = "unstable simulation at step " + std::to_string(step) + ": particle " +
                          std::to_string(atoms.tag[i]);
  if (!finite(i)) throw EngineError(who + " has a non-finite position or velocity");
  throw EngineError(who + " moves at " + format_g(norm(v[i])) +
                    " m/s, more than half its radius per time step");
}

void Simulation::handle_lost_particles() {
  // Most calls find every particle inside the box: each thread looks at its own share first
  // (see check_health), and only a particle outside makes the serial pass below run.
  // Outside the box along axis k (a periodic box is half-open); read at each call, as the
  // serial pass widens a shrink-wrapped box.
  auto outside_along = [this](double c, int k) {
    return c < domain.lo[k] || (domain.periodic(k) ? c >= domain.hi[k] : c > domain.hi[k]);
  };
  const Vec3* const x_all = atoms.x.data();
  std::atomic<bool> outside{false};
  neighbor.partition().for_each(atoms.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      for (int k = 0; k < 3; ++k)
        if (outside_along(x_all[i][k], k)) {
          outside.store(true, std::memory_order_relaxed);
          return;
        }
  });
  if (!outside.load()) return;
  std::vector<char> lost(atoms.size(), 0);
  bool any_lost = false;
  for (std::size_t i = 0; i < atoms.size(); ++i) {
    Vec3& x = atoms.x[i];
    for (int k = 0; k < 3; ++k) {
      if (!outside_along(x[k], k)) continue;
      const double lo = domain.lo[k], hi = domain.hi[k];
      if (domain.periodic(k)) {
        const double len = hi - lo;
        while (x[k] < lo) x[k] += len;
        while (x[k] >= hi) x[k] -= len;
      } else if (domain.boundary[k] == 'f') {
        lost[i] = 1;
        any_lost = true;
      } else {  // shrink-wrapped: the box follows the particles
        domain.lo[k] = std::min(lo, x[k]);
        domain.hi[k] = std::max(hi, x[k]);
      }
    }
  }
  if (!any_lost) return;
  const long n_lost = std::count(lost.begin(), lost.end(), 1);
  if (!thermo.lost_ignore)
    throw EngineError("lost " + std::to_string(n_lost) + " particles through a fixed boundary at step " +
                      std::to_string(step) + " (use thermo_modify lost ignore to delete them)");
  atoms.remove(lost);
  particles_changed();
}

void Simulation::check_timestep() {
  if (atoms.size() == 0) return;  // checked again once the first particles are inserted
  timestep_checked_ = true;
  // Rayleigh time of the smallest particle of each type present (LIGGGHTS check/timestep/gran).
  double t_rayleigh = 1e300;
  double rmin = 1e300, rho_of_rmin = 0.0;
  for (std::size_t i = 0; i < atoms.size(); ++i) {
    const int t = atoms.type[i];
    const double y = material.youngs_modulus(t), nu = material.poissons_ratio(t);
    const double g = y / (2.0 * (1.0 + nu));
    const double tr = M_PI * atoms.radius[i] * std::sqrt(atoms.density[i] / g) /
                      (0.1631 * nu + 0.8766);
    t_rayleigh = std::min(t_rayleigh, tr);
    if (atoms.radius[i] < rmin) {
      rmin = atoms.radius[i];
      rho_of_rmin = atoms.density[i];
    }
  }
  // Hertz contact time at the largest expected impact speed: particle and wall speeds, and a
  // free fall over the box height.
  double vmax = 0.0;
  for (const Vec3& v : atoms.v) vmax = std::max(vmax, norm(v));
  for (const auto& f : fixes) vmax = std::max(vmax, f->max_wall_speed());
  vmax = std::max(vmax, std::sqrt(2.0 * 9.81 * (domain.hi.z - domain.lo.z)));
  const double y = material.youngs_modulus(atoms.type[0]), nu = material.poissons_ratio(atoms.type[0]);
  const double y_star = y / (2.0 * (1.0 - nu * nu));
  const double r_star = 0.5 * rmin, m_star = 0.5 * 4.0 / 3.0 * M_PI * rmin * rmin * rmin * rho_of_rmin;
  const double t_hertz =
      2.87 * std::pow(m_star * m_star / (r_star * y_star * y_star * vmax), 0.2);
  std::ostringstream os;
  os << "time step " << format_g(dt) << " s = " << format_g(100.0 * dt / t_rayleigh, 3)
     << " % of the Rayleigh time and " << format_g(100.0 * dt / t_hertz, 3)
     << " % of the Hertz time (impact speed " << format_g(vmax, 3) << " m/s)";
  if (log_.is_open()) log_ << os.str() << '\n';
  if (dt > 0.2 * t_rayleigh || dt > 0.2 * t_hertz)
    warning(os.str() + ": above 20 %, the simulation may be inaccurate or unstable");
}

void Simulation::setup_run() {
  if (!domain.defined) throw EngineError("run before create_box");
  if (!pair) throw EngineError("run before pair_style gran");
  material.build(properties, ntypes, soft_particles, hard_particles, pair->spec().rolling_epsd2,
                 pair->spec().cohesion_sjkr);
  for (auto& f : fixes) f->init();
  handle_lost_particles();
  timestep_checked_ = false;
  check_timestep();
  neighbor.force_rebuild();
  neighbor.build(atoms, domain);
  last_build_step_ = step;
  setting_up_ = true;
  compute_forces();
  for (auto& f : fixes) f->setup();
  setting_up_ = false;
}

void Simulation::integrate_step() {
  ++step;
  time += dt;
  for (auto& f : fixes) f->initial_integrate();
  for (auto& f : fixes) f->post_integrate();
  for (auto& f : fixes) f->pre_exchange();
  if (!timestep_checked_) check_timestep();
  if (neighbor.due(atoms, step - last_build_step_)) {
    handle_lost_particles();
    // Keep particles that are close in space close in memory: a large gain in cache hits for
    // the pair loop at a cost of one sort per few rebuilds.
    if (neighbor.builds() % 8 == 0) atoms.permute(spatial_order(atoms, 2.0 * max_radius() + neighbor.skin));
    neighbor.build(atoms, domain);
    last_build_step_ = step;
  }
  pair_forces();
  force_hooks(true);
  for (auto& f : fixes) f->end_of_step();
}

void Simulation::run(const Command& command) {
  const auto& a = command.args;
  require_args(a, 1, "run N [upto] [every M \"command\" ...]");
  long n = parse_int(a[0], "run N");
  std::size_t k = 1;
  long every = 0;
  bool pre = true;
  std::vector<std::string> every_commands;
  while (k < a.size()) {
    if (a[k] == "upto") {
      n -= step;
      ++k;
    } else if (a[k] == "every") {
      if (k + 1 >= a.size()) throw EngineError("run every needs M and commands");
      every = parse_int(a[k + 1], "run every M");
      if (every <= 0) throw EngineError("run every M must be > 0");
      every_commands.assign(a.begin() + k + 2, a.end());
      if (every_commands.size() == 1 && every_commands[0] == "NULL") every_commands.clear();
      k = a.size();
    } else if ((a[k] == "pre" || a[k] == "post") && k + 1 < a.size()) {
      // LAMMPS run keywords take yes or no only. `post` selects the length of the timing
      // summary, which this engine does not print.
      if (a[k + 1] != "yes" && a[k + 1] != "no")
        throw EngineError("'" + a[k] + "' expects yes or no, got '" + a[k + 1] + "'");
      if (a[k] == "pre") pre = a[k + 1] == "yes";
      k += 2;
    } else {
      throw EngineError("unknown run keyword '" + a[k] + "'");
    }
  }
  if (n < 0) throw EngineError("run length is negative");
  // LIGGGHTS refuses more than 2^31-1 steps in one run ("Invalid run command N size").
  if (n > 2147483647L) throw EngineError("run length " + std::to_string(n) + " exceeds 2147483647");
  // `run N every M cmds`: N/M chained runs of M steps with the commands after each.
  const long chunk = every > 0 ? every : n;
  long remaining = n;
  // `pre no` after an earlier run (with `every`: for the chunks after the first): LIGGGHTS
  // neither initialises nor sets up (no neighbour build, no step-0 forces; the forces of the
  // last step carry over). That is exact only when nothing the set-up would take into account
  // has changed, so other cases are refused.
  bool skip_setup = !pre && has_run_ && every == 0;
  if (skip_setup) {
    std::vector<const Fix*> now;
    for (const auto& f : fixes) now.push_back(f.get());
    if (changed_since_run_ || now != fixes_at_run_)
      throw EngineError(
          "'pre no' after particles or fixes changed since the last run (LIGGGHTS would run "
          "without setting them up); use 'pre yes'");
  }
  do {
    const long this_run = std::min(chunk, remaining);
    run_start_step = step;
    run_end_step = step + this_run;
    if (!skip_setup) setup_run();
    skip_setup = !pre;
    thermo.header(*this);
    thermo.row(*this);
    for (auto& d : dumps) d->write();
    Progress progress(options_.progress, this_run);
    const auto t0 = std::chrono::steady_clock::now();
    for (long s = 0; s < this_run; ++s) {
      integrate_step();
      if (step % 10 == 0 || s + 1 == this_run) check_health();
      const bool last = step == run_end_step;
      if ((thermo.every > 0 && step % thermo.every == 0) || last) thermo.row(*this);
      for (auto& d : dumps)
        if (d->every() > 0 && step % d->every() == 0) d->write();
      progress.update(s + 1, atoms.size());
    }
    progress.finish();
    for (auto& f : fixes) f->post_run();
    if (deep_overlaps_.steps() > 0) {
      std::ostringstream os;
      os << deep_overlaps_.steps() << " of " << this_run
         << " steps of this run had a contact overlapping by more than "
         << format_g(100.0 * DeepOverlaps::kRatio, 3) << " % of a radius, from step "
         << deep_overlaps_.first_step() << "; deepest "
         << format_g(100.0 * deep_overlaps_.worst(), 3) << " %, particle " << deep_overlaps_.tag()
         << " against " << deep_overlaps_.partner();
      warning(os.str());
      deep_overlaps_.clear();
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::ostringstream os;
    os << "Loop time of " << format_g(secs, 6) << " on " << omp_get_max_threads()
       << " threads for " << this_run << " steps with " << atoms.size() << " atoms";
    if (secs > 0 && this_run > 0)
      os << " (" << format_g(static_cast<double>(this_run) * atoms.size() / secs, 4)
         << " particle-steps/s, " << neighbor.builds() << " neighbour builds)";
    message(os.str());
    remaining -= this_run;
    has_run_ = true;
    changed_since_run_ = false;
    fixes_at_run_.clear();
    for (const auto& f : fixes) fixes_at_run_.push_back(f.get());
    if (every > 0)
      for (const auto& c : every_commands) input().run_line(c, command.where);
    // The commands run between chunks may change the system, which `pre no` would not set up.
    if (skip_setup) {
      std::vector<const Fix*> now;
      for (const auto& f : fixes) now.push_back(f.get());
      if (changed_since_run_ || now != fixes_at_run_)
        throw EngineError(
            "'pre no' with 'every' commands that change particles or fixes (LIGGGHTS would run "
            "without setting them up); use 'pre yes'");
    }
  } while (remaining > 0);
}

}  // namespace dem
