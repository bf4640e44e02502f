// Tests of how work is split between threads (the particle partition, balanced by the contacts
// the neighbour list marks as touching at a build) and of the contact histories a neighbour
// build keeps.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <set>
#include <utility>
#include <vector>

#include "contact/contact_types.h"
#include "core/domain.h"
#include "core/neighbor.h"
#include "core/particles.h"
#include "core/threads.h"
#include "unit_test.h"

using dem::Vec3;

namespace {

// A closed 2 m cube around the origin.
dem::Domain closed_box() {
  dem::Domain box;
  box.boundary = {'f', 'f', 'f'};
  box.lo = Vec3{-1, -1, -1};
  box.hi = Vec3{1, 1, 1};
  return box;
}

// Spheres of 1 cm radius at the given centres, tags 1, 2, ...
dem::Particles spheres_at(std::initializer_list<Vec3> centres) {
  dem::Particles p;
  for (const Vec3& c : centres)
    p.add(static_cast<std::int64_t>(p.size()) + 1, 1, 1u, c, 0.01, 2500.0);
  return p;
}

// A list with a 2 mm skin, built once.
dem::NeighborList list_of(const dem::Particles& p, const dem::Domain& box) {
  dem::NeighborList list;
  list.skin = 0.002;
  list.build(p, box);
  return list;
}

}  // namespace

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

TEST_CASE("neighbour list: a rebuild keeps the history of the pairs touching at the build") {
  // As LIGGGHTS 3.8: what counts is the geometry at the build (the positions of the force
  // evaluation that follows it), not the touching flag of the previous evaluation.
  const dem::Domain box = closed_box();
  // 1-2 overlap, 2-3 are within the skin but apart.
  dem::Particles p =
      spheres_at({Vec3{0.0, 0.0, 0.0}, Vec3{0.019, 0.0, 0.0}, Vec3{0.0395, 0.0, 0.0}});
  dem::NeighborList list = list_of(p, box);
  CHECK_EQ(list.pairs(), std::size_t{2});
  // The flags follow the geometry of the build; a fresh list has no history.
  CHECK_EQ(static_cast<int>(list.touching[0]), 1);
  CHECK_EQ(static_cast<int>(list.touching[1]), 0);
  CHECK_EQ(list.history[0], 0.0);
  CHECK_EQ(list.history[dem::kHistorySize], 0.0);

  // 1-2 touch at the build: the spring is kept, even flagged apart at the last evaluation.
  // 2-3 touched at the last evaluation but are apart at the build: the spring is dropped.
  list.history[0] = 1e-6;
  list.touching[0] = 0;
  list.history[dem::kHistorySize] = 2e-6;
  list.touching[1] = 1;
  list.force_rebuild();
  list.build(p, box);
  CHECK_EQ(list.pairs(), std::size_t{2});
  CHECK_EQ(static_cast<int>(list.touching[0]), 1);
  CHECK_EQ(static_cast<int>(list.touching[1]), 0);
  CHECK_EQ(list.history[0], 1e-6);
  CHECK_EQ(list.history[dem::kHistorySize], 0.0);

  // 2-3 opened earlier (flag 0, spring kept while in the list) and touch again at the build:
  // the spring is resumed. 1-2 moved apart (still in the list): their spring is dropped.
  list.history[dem::kHistorySize] = 3e-6;
  list.touching[1] = 0;
  p.x[0] = Vec3{-0.0015, 0.0, 0.0};
  p.x[2] = Vec3{0.0385, 0.0, 0.0};
  list.force_rebuild();
  list.build(p, box);
  CHECK_EQ(list.pairs(), std::size_t{2});
  CHECK_EQ(static_cast<int>(list.touching[0]), 0);
  CHECK_EQ(static_cast<int>(list.touching[1]), 1);
  CHECK_EQ(list.history[0], 0.0);
  CHECK_EQ(list.history[dem::kHistorySize], 3e-6);
}

TEST_CASE("neighbour list: after a reordering, histories follow the tags and the build geometry") {
  const dem::Domain box = closed_box();
  // 1-2 overlap, 2-3 are within the skin but apart.
  dem::Particles p =
      spheres_at({Vec3{0.0, 0.0, 0.0}, Vec3{0.019, 0.0, 0.0}, Vec3{0.0395, 0.0, 0.0}});
  dem::NeighborList list = list_of(p, box);
  list.history[0] = 1e-6;                  // 1-2, touching
  list.history[dem::kHistorySize] = 2e-6;  // 2-3, apart
  list.touching[1] = 1;                    // 2-3 touched at the last evaluation
  // Reversed order: tags 3, 2, 1. The pairs are now (3, 2) and (2, 1), listed from the
  // particle of lower index, so the 1-2 history is seen from particle 2: its sign flips.
  p.permute({2, 1, 0});
  list.build(p, box);
  CHECK_EQ(list.pairs(), std::size_t{2});
  CHECK_EQ(static_cast<int>(list.touching[0]), 0);  // 3-2
  CHECK_EQ(static_cast<int>(list.touching[1]), 1);  // 2-1
  CHECK_EQ(list.history[0], 0.0);
  CHECK_EQ(list.history[dem::kHistorySize], -1e-6);
}

TEST_CASE("neighbour list: a bin with more candidates than the scan buffer finds every pair") {
  // One big sphere makes the bins 2 x 5 mm wide; 900 small ones fill one, so its stencil holds
  // far more candidates than the search's stack buffer and takes its other path.
  dem::Particles p;
  const dem::Domain box = closed_box();
  p.add(1, 1, 1u, Vec3{0.0, 0.0, 0.0}, 0.005, 2500.0);
  for (int k = 0; k < 900; ++k) {
    const double s = static_cast<double>(k);
    p.add(k + 2, 1, 1u, 0.006 * Vec3{std::sin(1.7 * s), std::cos(2.3 * s), std::sin(0.37 * s)},
          0.0004, 2500.0);
  }
  dem::NeighborList list;
  list.skin = 0.0002;
  list.build(p, box);
  std::set<std::pair<int, int>> found, expected;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int k = list.first[i]; k < list.first[i + 1]; ++k)
      found.insert({static_cast<int>(i), list.partner[k]});
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double reach = p.radius[i] + p.radius[j] + list.skin;
      if (dem::norm2(p.x[i] - p.x[j]) < reach * reach)
        expected.insert({static_cast<int>(i), static_cast<int>(j)});
    }
  }
  CHECK(expected.size() > 900);
  CHECK(found == expected);
  CHECK_EQ(list.pairs(), expected.size());
}

TEST_CASE("neighbour list: a particle added with a reordering starts without history") {
  const dem::Domain box = closed_box();
  dem::Particles p = spheres_at({Vec3{0.0, 0.0, 0.0}, Vec3{0.019, 0.0, 0.0}});
  dem::NeighborList list = list_of(p, box);
  CHECK_EQ(list.pairs(), std::size_t{1});
  list.history[0] = 1e-6;  // 1-2
  // Tag 3 arrives touching particle 1, and the order changes: tags 2, 3, 1.
  p.add(3, 1, 1u, Vec3{0.0, 0.019, 0.0}, 0.01, 2500.0);
  p.permute({1, 2, 0});
  list.build(p, box);
  // Pairs by index: (0, 2) is tags 2-1, (1, 2) is tags 3-1; 2 and 3 are apart.
  CHECK_EQ(list.pairs(), std::size_t{2});
  CHECK_EQ(list.partner[0], 2);
  CHECK_EQ(list.partner[1], 2);
  CHECK_EQ(list.history[0], -1e-6);  // seen from particle 2 now: the sign flips
  CHECK_EQ(list.history[dem::kHistorySize], 0.0);
}
