// Tests of how work is split between threads: the particle partition and the per-pair
// "touching" flags of the neighbour list that let the pair loop skip the history of pairs apart.
#include <cstddef>
#include <vector>

#include "contact/contact_types.h"
#include "core/domain.h"
#include "core/neighbor.h"
#include "core/particles.h"
#include "core/threads.h"
#include "unit_test.h"

using dem::Vec3;

TEST_CASE("partition: contiguous shares of about equal weight") {
  // Ten particles; the first five weigh 10 each, the last five 1 each (total 55).
  std::vector<long> prefix{0};
  for (int i = 0; i < 10; ++i) prefix.push_back(prefix.back() + (i < 5 ? 10 : 1));
  dem::ParticlePartition part;
  part.balance(prefix, 2);
  const dem::ParticleShare a = part.share(10, 0, 2), b = part.share(10, 1, 2);
  CHECK_EQ(a.begin, std::size_t{0});
  CHECK_EQ(a.end, b.begin);
  CHECK_EQ(b.end, std::size_t{10});
  // Half the weight, 27.5, is reached after three heavy particles (30).
  CHECK_EQ(a.end, std::size_t{3});
  // Balanced for another particle count or team: equal counts.
  CHECK_EQ(part.share(12, 1, 2).begin, std::size_t{6});
  CHECK_EQ(part.share(10, 1, 3).begin, std::size_t{3});
  CHECK_EQ(part.share(10, 2, 3).end, std::size_t{10});
}

TEST_CASE("partition: every thread of a team covers its share exactly once") {
  std::vector<long> prefix{0};
  for (int i = 0; i < 1000; ++i) prefix.push_back(prefix.back() + 1 + (i % 7));
  dem::ParticlePartition part;
  part.balance(prefix, 4);
  std::vector<int> seen(1000, 0);
  for (int t = 0; t < 4; ++t) {
    const dem::ParticleShare s = part.share(1000, t, 4);
    for (std::size_t i = s.begin; i < s.end; ++i) ++seen[i];
    const long w = prefix[s.end] - prefix[s.begin];
    CHECK(w > prefix[1000] / 4 - 8 && w < prefix[1000] / 4 + 8);
  }
  for (int c : seen) CHECK_EQ(c, 1);
}

TEST_CASE("neighbour list: a rebuild keeps the history of touching pairs only") {
  dem::Particles p;
  dem::Domain box;
  box.boundary = {'f', 'f', 'f'};
  box.lo = Vec3{-1, -1, -1};
  box.hi = Vec3{1, 1, 1};
  // 1-2 overlap, 2-3 are within the skin but apart.
  p.add(1, 1, 1u, Vec3{0.0, 0.0, 0.0}, 0.01, 2500.0);
  p.add(2, 1, 1u, Vec3{0.019, 0.0, 0.0}, 0.01, 2500.0);
  p.add(3, 1, 1u, Vec3{0.0395, 0.0, 0.0}, 0.01, 2500.0);
  dem::NeighborList list;
  list.skin = 0.002;
  list.build(p, box);
  CHECK_EQ(list.pairs(), std::size_t{2});
  // A fresh list has no history, so nothing is touching yet.
  CHECK_EQ(list.touching[0] + list.touching[1], 0);
  list.history[0] = 1e-6;  // the 1-2 contact has a tangential spring
  list.touching[0] = 1;
  // The 2-3 pair touched before and opened: its history is stale (kept until the build).
  list.history[dem::kHistorySize] = 2e-6;
  list.force_rebuild();
  list.build(p, box);
  CHECK_EQ(list.pairs(), std::size_t{2});
  CHECK_EQ(static_cast<int>(list.touching[0]), 1);
  CHECK_EQ(static_cast<int>(list.touching[1]), 0);
  CHECK_EQ(list.history[0], 1e-6);
  CHECK_EQ(list.history[dem::kHistorySize], 0.0);
}
