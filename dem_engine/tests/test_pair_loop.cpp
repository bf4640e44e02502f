// Tests of the pair loop's batches: a particle with more touching partners than one batch
// holds (its pairs are split across batches) gets exactly the sum of its contacts, each as the
// contact law gives it alone, added in the order of the neighbour list; and of its threads:
// two threads, which exchange the forces on the pairs across their shares, give the forces of
// one up to the order of the sums.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <vector>

#include "contact/contact_model.h"
#include "contact/material.h"
#include "core/domain.h"
#include "core/neighbor.h"
#include "core/particles.h"
#include "core/properties.h"
#include "unit_test.h"

using dem::Vec3;

namespace {

constexpr double kBigRadius = 0.01, kSmallRadius = 0.001, kDensity = 2500.0;

dem::MaterialTable material() {
  dem::PropertyStore props;
  auto per_type = [](double v) { return dem::GlobalProperty{"peratomtype", 1, {v}}; };
  auto per_pair = [](double v) { return dem::GlobalProperty{"peratomtypepair", 1, {v}}; };
  props.set("youngsModulus", per_type(5e6), "m1");
  props.set("poissonsRatio", per_type(0.4), "m2");
  props.set("coefficientRestitution", per_pair(0.6), "m3");
  props.set("coefficientFriction", per_pair(0.5), "m4");
  props.set("coefficientRollingFriction", per_pair(0.3), "m5");
  dem::MaterialTable table;
  table.build(props, 1, true, false, true, false);
  return table;
}

// The big sphere (index 0) and the small ones given, with velocities that make every part of
// the law (normal, sliding or sticking tangential, rolling) non-zero.
dem::Particles cluster(const std::vector<Vec3>& small_centres) {
  dem::Particles p;
  p.add(1, 1, 1u, Vec3{0.0, 0.0, 0.0}, kBigRadius, kDensity);
  p.v[0] = Vec3{0.01, -0.02, 0.005};
  p.omega[0] = Vec3{0.5, 0.1, -0.3};
  for (std::size_t k = 0; k < small_centres.size(); ++k) {
    const std::size_t i = p.add(static_cast<std::int64_t>(k) + 2, 1, 1u, small_centres[k],
                                kSmallRadius, kDensity);
    const double s = static_cast<double>(k);
    p.v[i] = Vec3{0.03 * std::sin(s), 0.02 * std::cos(1.7 * s), -0.01 * std::sin(0.3 * s)};
    p.omega[i] = Vec3{2.0 * std::cos(s), -1.0 * std::sin(2.3 * s), 0.5};
  }
  return p;
}

// Forces and torques after one force evaluation of the pair loop, on one thread (below 1 000
// particles) or on up to `threads`; returns the list (with the histories the loop wrote).
// The pair forces of `steps` steps on `threads` threads (same list; before each later step the
// velocities and spins change, so that every step's forces depend on that step's values).
dem::NeighborList evaluate(dem::Particles& p, const dem::MaterialTable& table, long& contacts,
                           int threads = 1, int steps = 1) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  dem::Domain box;
  box.boundary = {'f', 'f', 'f'};
  box.lo = Vec3{-1, -1, -1};
  box.hi = Vec3{1, 1, 1};
  dem::NeighborList list;
  list.skin = 1e-4;
  list.build(p, box);
  dem::ModelSpec spec;
  spec.rolling_epsd2 = true;
  const std::unique_ptr<dem::ContactModel> model = dem::make_contact_model(spec);
  dem::PairScratch scratch;
  dem::PairForceArgs args{p, list, table, box, 1e-5, true, 0u, scratch};
  for (int s = 0; s < steps; ++s) {
    if (s > 0)
      for (std::size_t i = 0; i < p.size(); ++i) {
        p.v[i] = Vec3{-p.v[i].y, p.v[i].x, 0.5 * p.v[i].z};
        p.omega[i] = Vec3{p.omega[i].z, -p.omega[i].x, p.omega[i].y};
      }
    model->pair_forces(args);
  }
  contacts = args.contacts;
  omp_set_num_threads(before);
  return list;
}

bool same(const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

}  // namespace

TEST_CASE("pair loop: a particle with more contacts than a batch holds gets their exact sum") {
  // 250 small spheres on a sphere around the big one, each overlapping it by 1e-4 m and more
  // than a skin apart from each other (Fibonacci points: about 2.4 mm between neighbours).
  const int n = 250;
  std::vector<Vec3> centres;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  const double reach = kBigRadius + kSmallRadius - 1e-4;
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / n, r = std::sqrt(1.0 - z * z);
    const double phi = golden * k;
    centres.push_back(reach * Vec3{r * std::cos(phi), r * std::sin(phi), z});
  }
  const dem::MaterialTable table = material();
  dem::Particles all = cluster(centres);
  long contacts = 0;
  evaluate(all, table, contacts);
  CHECK_EQ(contacts, static_cast<long>(n));

  // Each contact alone: the big sphere and one small one, in the list's order (by index).
  Vec3 force_sum, torque_sum;
  int exact = 0;
  for (int k = 0; k < n; ++k) {
    dem::Particles pair = cluster({centres[static_cast<std::size_t>(k)]});
    pair.v[1] = all.v[static_cast<std::size_t>(k) + 1];
    pair.omega[1] = all.omega[static_cast<std::size_t>(k) + 1];
    long one = 0;
    evaluate(pair, table, one);
    CHECK_EQ(one, 1L);
    CHECK(norm2(pair.f[0]) > 0.0);
    force_sum += pair.f[0];
    torque_sum += pair.torque[0];
    const std::size_t i = static_cast<std::size_t>(k) + 1;
    exact += same(all.f[i], pair.f[1]) && same(all.torque[i], pair.torque[1]);
  }
  CHECK_EQ(exact, n);
  CHECK(same(all.f[0], force_sum));
  CHECK(same(all.torque[0], torque_sum));
}

TEST_CASE("pair loop: two and three threads give the forces, torques and histories of one") {
  // A jittered cubic lattice of 14^3 spheres, 1 mm radius, 1.95 mm apart: each overlaps its
  // lattice neighbours, with velocities and spins that vary from particle to particle.
  const int side = 14;
  const double r = 0.001, spacing = 0.00195;
  dem::Particles base;
  for (int a = 0; a < side; ++a)
    for (int b = 0; b < side; ++b)
      for (int c = 0; c < side; ++c) {
        const double s = static_cast<double>(base.size());
        const Vec3 jitter = 2e-5 * Vec3{std::sin(1.3 * s), std::cos(2.1 * s), std::sin(0.7 * s)};
        const std::size_t i = base.add(static_cast<std::int64_t>(base.size()) + 1, 1, 1u,
                                       spacing * Vec3{1.0 * a, 1.0 * b, 1.0 * c} + jitter,
                                       r, kDensity);
        base.v[i] = Vec3{0.02 * std::sin(s), 0.03 * std::cos(0.9 * s), -0.01 * std::sin(2.0 * s)};
        base.omega[i] = Vec3{3.0 * std::cos(s), -2.0 * std::sin(1.1 * s), std::cos(0.4 * s)};
      }
  const dem::MaterialTable table = material();
  // Three steps: a thread reads its partners in the next share from copies made each step.
  const int steps = 3;
  dem::Particles one = base;
  long contacts_one = 0;
  const dem::NeighborList list_one = evaluate(one, table, contacts_one, 1, steps);
  CHECK_EQ(contacts_one, 3L * side * side * (side - 1));  // the lattice neighbours
  for (const int threads : {2, 3}) {
    dem::Particles many = base;
    long contacts_many = 0;
    const dem::NeighborList list_many = evaluate(many, table, contacts_many, threads, steps);
    CHECK_EQ(contacts_many, contacts_one);
    // Pairs across the first two shares, whose partners the first thread reads from copies
    // and whose forces it hands to the second.
    const dem::ParticleShare first_share = list_many.partition().share(base.size(), 0, threads);
    int across = 0;
    for (std::size_t i = first_share.begin; i < first_share.end; ++i)
      for (int k = list_many.first[i]; k < list_many.first[i + 1]; ++k)
        across += static_cast<std::size_t>(list_many.partner[k]) >= first_share.end;
    CHECK(across > side * side);
    // Forces differ only by the order of their sums: within a few roundings of the largest.
    double f_max = 0.0, t_max = 0.0, f_diff = 0.0, t_diff = 0.0;
    for (std::size_t i = 0; i < base.size(); ++i) {
      f_max = std::max(f_max, dem::norm(one.f[i]));
      t_max = std::max(t_max, dem::norm(one.torque[i]));
      f_diff = std::max(f_diff, dem::norm(one.f[i] - many.f[i]));
      t_diff = std::max(t_diff, dem::norm(one.torque[i] - many.torque[i]));
    }
    CHECK(f_max > 0.0 && t_max > 0.0);
    CHECK(f_diff <= 1e-14 * f_max);
    CHECK(t_diff <= 1e-14 * t_max);
    // The histories are per pair, not sums: the same bits.
    CHECK(list_one.history == list_many.history);
  }
}
