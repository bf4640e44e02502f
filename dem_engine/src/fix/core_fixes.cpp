// Fix styles of the core: material properties, gravity, integration, freezing.
#include <algorithm>
#include <cmath>
#include <memory>

#include "core/numbers.h"
#include "core/threads.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "fix/fix.h"

namespace dem {
namespace {

// fix ID all property/global NAME STYLE args: stores a global material property.
class FixPropertyGlobal : public Fix {
 public:
  FixPropertyGlobal(Simulation& sim, const Command& c) : Fix(sim, c) {
    const auto& a = args();
    require_args(a, 3, "fix ID all property/global NAME scalar|vector|peratomtype|peratomtypepair|matrix values...");
    GlobalProperty p;
    p.style = a[1];
    std::size_t first_value = 2;
    if (p.style == "peratomtypepair" || p.style == "matrix") {
      p.n = static_cast<int>(parse_int(a[2], a[0] + " matrix size"));
      if (p.n < 1) throw EngineError(a[0] + ": matrix size must be >= 1");
      first_value = 3;
    } else if (p.style != "scalar" && p.style != "vector" && p.style != "peratomtype") {
      throw EngineError("unknown property/global style '" + p.style + "'");
    }
    for (std::size_t i = first_value; i < a.size(); ++i)
      p.values.push_back(parse_double(a[i], a[0] + " value " + std::to_string(i - first_value + 1)));
    if (p.values.empty()) throw EngineError(a[0] + ": no values given");
    if (p.n > 0 && static_cast<int>(p.values.size()) != p.n * p.n)
      throw EngineError(a[0] + ": a " + std::to_string(p.n) + "x" + std::to_string(p.n) +
                        " matrix needs " + std::to_string(p.n * p.n) + " values, got " +
                        std::to_string(p.values.size()));
    if (p.style == "scalar" && p.values.size() != 1)
      throw EngineError(a[0] + ": scalar takes one value");
    sim.properties.set(a[0], p, id());
  }
};

// fix ID group gravity G vector X Y Z
class FixGravity : public Fix {
 public:
  FixGravity(Simulation& sim, const Command& c) : Fix(sim, c) {
    const auto& a = args();
    if (a.size() != 5 || a[1] != "vector")
      throw EngineError("usage: fix ID group gravity MAGNITUDE vector X Y Z");
    const double g = parse_double(a[0], "gravity magnitude");
    const Vec3 dir{parse_double(a[2], "x"), parse_double(a[3], "y"), parse_double(a[4], "z")};
    const double len = norm(dir);
    if (len == 0.0) throw EngineError("gravity direction is zero");
    accel_ = (g / len) * dir;
  }
  HookWork post_force_work() override {
    HookWork work;
    work.share = [this](std::size_t begin, std::size_t end) {
      auto& P = sim_.atoms;
      const std::uint32_t bit = group_bit();
      // Locals: a store to a force could alias accel_, which would be reloaded after each one.
      const std::uint32_t* const mask = P.mask.data();
      const double* const mass = P.rmass.data();
      Vec3* const f = P.f.data();
      const Vec3 a = accel_;
      for (std::size_t i = begin; i < end; ++i)
        if (mask[i] & bit) f[i] += mass[i] * a;
    };
    return work;
  }
  const Vec3& acceleration() const { return accel_; }

 private:
  Vec3 accel_;
};

// fix ID group nve/sphere: velocity Verlet for translation and rotation of spheres.
class FixNveSphere : public Fix {
 public:
  FixNveSphere(Simulation& sim, const Command& c) : Fix(sim, c) {
    if (!args().empty()) throw EngineError("fix nve/sphere takes no arguments here");
  }
  void initial_integrate() override {
    update_inverses();
    sim_.neighbor.partition().for_each(sim_.atoms.size(), share_kick(true));
  }
  HookWork final_integrate_work() override {
    HookWork work;
    work.before = [this] { update_inverses(); };
    work.share = share_kick(false);
    return work;
  }

 private:
  // The kick (with drift, also the drift) of one share; the inverses must be up to date when
  // it runs.
  std::function<void(std::size_t, std::size_t)> share_kick(bool drift) {
    return [this, drift](std::size_t begin, std::size_t end) {
      auto& P = sim_.atoms;
      const double dt = sim_.dt, half = 0.5 * dt;
      // Everything the loop reads as locals (copied into move): a store to a velocity could
      // alias any double reached through a reference, which would be reloaded after every
      // store. The arrays are taken here, after update_inverses may have moved them.
      const Arrays a{P.mask.data(), inv_m_.data(), inv_i_.data(), P.f.data(), P.torque.data(),
                     P.v.data(),    P.omega.data(), P.x.data()};
      if (drift) move<true>(a, group_bit(), dt, half, begin, end);
      else move<false>(a, group_bit(), dt, half, begin, end);
    };
  }

  struct Arrays {
    const std::uint32_t* mask;
    const double *inv_m, *inv_i;
    const Vec3 *f, *torque;
    Vec3 *v, *omega, *x;
  };

  // Velocity Verlet half kick of particles begin .. end - 1 in the group `bit`, and with Drift
  // the full-step drift of their positions.
  template <bool Drift>
  static void move(Arrays a, std::uint32_t bit, double dt, double half, std::size_t begin,
                   std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!(a.mask[i] & bit)) continue;
      a.v[i] += (half * a.inv_m[i]) * a.f[i];
      a.omega[i] += (half * a.inv_i[i]) * a.torque[i];
      if constexpr (Drift) a.x[i] += dt * a.v[i];
    }
  }

  // Inverse masses and inertias, recomputed only when particles or their masses change, not
  // four divisions per particle and step (the same values: 1 / m is computed the same way).
  void update_inverses() {
    const auto& P = sim_.atoms;
    if (inverses_of_ == P.mass_version() && inv_m_.size() == P.size()) return;
    const std::size_t n = P.size();
    inv_m_.resize(n);
    inv_i_.resize(n);
    const double* mass = P.rmass.data();
    const double* rad = P.radius.data();
    for (std::size_t i = 0; i < n; ++i) {
      inv_m_[i] = 1.0 / mass[i];
      inv_i_[i] = 1.0 / sphere_inertia(mass[i], rad[i]);
    }
    inverses_of_ = P.mass_version();
  }

  std::vector<double> inv_m_, inv_i_;
  std::uint64_t inverses_of_ = ~std::uint64_t{0};
};

// fix ID group freeze: zero force and torque on the group (LAMMPS semantics).
class FixFreeze : public Fix {
 public:
  FixFreeze(Simulation& sim, const Command& c) : Fix(sim, c) {
    if (!args().empty()) throw EngineError("fix freeze takes no arguments");
  }
  HookWork post_force_work() override {
    HookWork work;
    work.share = [this](std::size_t begin, std::size_t end) {
      auto& P = sim_.atoms;
      for (std::size_t i = begin; i < end; ++i)
        if (P.mask[i] & group_bit()) {
          P.f[i] = Vec3{};
          P.torque[i] = Vec3{};
        }
    };
    return work;
  }
};

template <class T>
FixFactory factory() {
  return [](Simulation& s, const Command& c) { return std::make_unique<T>(s, c); };
}

}  // namespace

void register_core_fix_styles(FixRegistry& r) {
  r["property/global"] = factory<FixPropertyGlobal>();
  r["gravity"] = factory<FixGravity>();
  r["nve/sphere"] = factory<FixNveSphere>();
  r["freeze"] = factory<FixFreeze>();
}

}  // namespace dem
