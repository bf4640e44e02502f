#pragma once
#include <cstdint>
#include <vector>

#include "contact/contact_types.h"
#include "core/domain.h"
#include "core/particles.h"
#include "core/threads.h"

namespace dem {

// Half neighbour list (each pair once, i < j) from cell binning with a skin. Contact history
// lives beside the list and survives rebuilds, matched by particle tags, for the pairs that
// touch at the positions of the build; the history of a pair that opened is kept while the pair
// stays in the list and dropped by a build at which it does not touch (LIGGGHTS semantics).
// Order of the particles along a cell grid (cells of size `cell`, x fastest), so that
// neighbours in space are neighbours in memory.
std::vector<std::size_t> spatial_order(const Particles& p, double cell);

class NeighborList {
 public:
  double skin = 1e-4;   // neighbor SKIN bin (m)
  int every = 1;        // neigh_modify every
  int delay = 0;        // neigh_modify delay
  bool check = true;    // neigh_modify check yes|no

  std::vector<int> first;         // size n+1: pairs of i are [first[i], first[i+1])
  std::vector<int> partner;       // j for every pair
  std::vector<double> history;    // kHistorySize doubles per pair
  // Per pair: 1 when the pair touched at its last evaluation (set by the pair loop, and at a
  // build for the pairs that touch at its positions). A build does not read it: it keeps the
  // histories of the pairs that touch at its own positions (see mark_touching).
  std::vector<std::uint8_t> touching;

  // True when every rebuild check is done at every step, so that no particle moves more than
  // skin/2 between two builds: anything farther than the skin at a build cannot touch before
  // the next one (walls use this to skip particles far from them).
  bool bounds_motion() const { return check && every <= 1 && delay <= 0; }
  // True when a rebuild is due at this step (displacement beyond skin/2, or forced).
  bool due(const Particles& p, long steps_since_build) const;
  void force_rebuild() { forced_ = true; }
  // The particles were given new tags: (old, new) pairs sorted by the old tag. Histories are
  // matched through the new tags at the next build; tags not listed match no pair any more, and
  // the histories of pairs whose two tags both changed are dropped (as LIGGGHTS loses them).
  void retag(const std::vector<std::pair<std::int64_t, std::int64_t>>& old_to_new);
  // Rebuilds the list; `extra_cutoff` widens the search (largest radius to be inserted).
  void build(const Particles& p, const Domain& domain);
  long builds() const { return builds_; }
  // The split of the particles between threads, balanced by contacts at every build.
  const ParticlePartition& partition() const { return partition_; }
  std::size_t pairs() const { return partner.size(); }

 private:
  // Sets `touching` from the positions of the build, drops the histories of the pairs apart
  // and balances the partition by contacts.
  void mark_touching(const Particles& p, const Domain& domain, int nthreads);

  std::vector<Vec3> x_at_build_;
  std::vector<std::int64_t> tags_at_build_;
  ParticlePartition partition_;
  std::vector<std::vector<int>> found_;  // partners per particle, reused between builds
  std::vector<Vec3> bin_x_;              // positions in bin order (build scratch)
  std::vector<double> bin_r_;            // radii in bin order (build scratch)
  // The list before the last build (first, partner, history), kept for its storage.
  std::vector<int> spare_first_, spare_partner_;
  std::vector<double> spare_history_;
  bool forced_ = true;
  long builds_ = 0;
};

}  // namespace dem
