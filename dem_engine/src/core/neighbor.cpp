#include "core/neighbor.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>

#include "core/threads.h"

namespace dem {

bool NeighborList::due(const Particles& p, long steps_since_build) const {
  if (forced_ || x_at_build_.size() != p.size()) return true;
  if (steps_since_build < delay || steps_since_build % std::max(every, 1) != 0) return false;
  if (!check) return true;
  const double limit2 = 0.25 * skin * skin;
  // Each thread scans its own share of the particles: one thread reading all positions would
  // pull them into its cache every step.
  std::atomic<bool> moved{false};
  partition_.for_each(p.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      if (norm2(p.x[i] - x_at_build_[i]) > limit2) {
        moved.store(true, std::memory_order_relaxed);
        return;
      }
  });
  return moved.load();
}

namespace {

// Candidates of one bin's stencil scanned through a stack buffer (see NeighborList::build).
constexpr int kScanBuffer = 512;

bool any_nonzero(const double* hist) {
  for (int c = 0; c < kHistorySize; ++c)
    if (hist[c] != 0.0) return true;
  return false;
}

// Bounding box of the positions of p (not empty) and its largest radius. Minima and maxima
// are the same in any order, so on any number of threads.
struct Bounds {
  Vec3 lo, hi;
  double rmax = 0.0;
};

Bounds bounds_of(const Particles& p, int nthreads) {
  const long n = static_cast<long>(p.size());
  double rmax = 0.0;
  double lo0 = p.x[0][0], lo1 = p.x[0][1], lo2 = p.x[0][2];
  double hi0 = lo0, hi1 = lo1, hi2 = lo2;
#pragma omp parallel for schedule(static) num_threads(nthreads) \
    reduction(max : rmax, hi0, hi1, hi2) reduction(min : lo0, lo1, lo2)
  for (long i = 0; i < n; ++i) {
    const Vec3& x = p.x[static_cast<std::size_t>(i)];
    rmax = std::max(rmax, p.radius[static_cast<std::size_t>(i)]);
    lo0 = std::min(lo0, x[0]);
    lo1 = std::min(lo1, x[1]);
    lo2 = std::min(lo2, x[2]);
    hi0 = std::max(hi0, x[0]);
    hi1 = std::max(hi1, x[1]);
    hi2 = std::max(hi2, x[2]);
  }
  return {{lo0, lo1, lo2}, {hi0, hi1, hi2}, rmax};
}

}  // namespace

std::vector<std::size_t> spatial_order(const Particles& p, double cell) {
  const std::size_t n = p.size();
  std::vector<std::size_t> order(n);
  if (n == 0) return order;
  const Bounds box = bounds_of(p, worker_threads(n));
  const Vec3& lo = box.lo;
  const Vec3& hi = box.hi;
  std::array<long, 3> nb{};
  for (int k = 0; k < 3; ++k) nb[k] = std::clamp(static_cast<long>((hi[k] - lo[k]) / cell) + 1, 1L, 1024L);
  std::vector<long> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    long c[3];
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<long>((p.x[i][k] - lo[k]) / cell), 0L, nb[k] - 1);
    key[i] = (c[2] * nb[1] + c[1]) * nb[0] + c[0];
  }
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  return order;
}

void NeighborList::retag(const std::vector<std::pair<std::int64_t, std::int64_t>>& old_to_new) {
  std::vector<char> changed(tags_at_build_.size(), 1);
  for (std::size_t i = 0; i < tags_at_build_.size(); ++i) {
    std::int64_t& t = tags_at_build_[i];
    const auto it = std::lower_bound(
        old_to_new.begin(), old_to_new.end(), t,
        [](const std::pair<std::int64_t, std::int64_t>& e, std::int64_t v) { return e.first < v; });
    const bool found = it != old_to_new.end() && it->first == t;
    changed[i] = !found || it->second != t;
    t = found ? it->second : 0;  // 0: no particle
  }
  // LIGGGHTS finds the history of a pair again through the id one particle recorded for the
  // other, so it survives when at least one of the two ids is unchanged.
  for (std::size_t i = 0; i + 1 < first.size() && i < changed.size(); ++i)
    for (int k = first[i]; k < first[i + 1]; ++k)
      if (changed[i] && changed[static_cast<std::size_t>(partner[k])]) {
        touching[static_cast<std::size_t>(k)] = 0;
        std::fill_n(&history[static_cast<std::size_t>(k) * kHistorySize], kHistorySize, 0.0);
      }
  forced_ = true;
}

void NeighborList::build(const Particles& p, const Domain& domain) {
  const std::size_t n = p.size();
  // Contact history transfer: when the particle order is unchanged since the last build, the
  // old and new partner lists of each particle are both sorted, so a linear merge matches them;
  // otherwise contacts are matched through the tags of their particles. All histories are
  // carried over here; mark_touching then keeps only those of the pairs that touch at the
  // positions of this build (see there).
  const bool same_order = tags_at_build_ == p.tag;
  // The previous list moves to the spare arrays and the new one is built in the storage of the
  // one before: no build allocates (and page-faults in) a fresh history array.
  spare_first_.swap(first);
  spare_partner_.swap(partner);
  spare_history_.swap(history);
  const std::vector<int>& old_first = spare_first_;
  const std::vector<int>& old_partner = spare_partner_;
  const std::vector<double>& old_history = spare_history_;
  // After a reordering (or particles added, removed or renumbered): each particle's index at
  // the last build, found through its tag (-1: not there then).
  std::vector<int> old_index;
  if (!same_order) {
    std::vector<std::pair<std::int64_t, int>> by_tag;
    by_tag.reserve(tags_at_build_.size());
    for (std::size_t i = 0; i < tags_at_build_.size() && i + 1 < old_first.size(); ++i)
      if (tags_at_build_[i] != 0) by_tag.emplace_back(tags_at_build_[i], static_cast<int>(i));
    std::sort(by_tag.begin(), by_tag.end());
    old_index.assign(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
      const auto it = std::lower_bound(by_tag.begin(), by_tag.end(),
                                       std::pair<std::int64_t, int>{p.tag[i], -1});
      if (it != by_tag.end() && it->first == p.tag[i]) old_index[i] = it->second;
    }
  }
  first.assign(n + 1, 0);
  x_at_build_ = p.x;
  tags_at_build_ = p.tag;
  forced_ = false;
  ++builds_;
  if (n == 0) {
    partner.clear();
    history.clear();
    mark_touching(p, domain, 1);
    return;
  }

  // The passes over all particles run on all threads: while particles pour in, the list is
  // rebuilt every few steps, and done on one thread they took a sixth of a build on two.
  const int nthreads = worker_threads(n);
  const long ln = static_cast<long>(n);
  const Bounds box = bounds_of(p, nthreads);
  Vec3 lo = box.lo, hi = box.hi;
  const double cutoff = 2.0 * box.rmax + skin;
  std::array<int, 3> nb{};
  std::array<double, 3> origin{}, inv{};
  for (int k = 0; k < 3; ++k) {
    if (domain.periodic(k)) {
      lo[k] = domain.lo[k];
      hi[k] = domain.hi[k];
    }
    const double len = std::max(hi[k] - lo[k], 1e-300);
    // Cap the bin count so sparse, spread-out systems do not allocate huge grids.
    nb[k] = std::clamp(static_cast<int>(len / cutoff), 1, 1024);
    origin[k] = lo[k];
    inv[k] = nb[k] / len;
  }
  auto bin_coord = [&](const Vec3& x, int k) {
    int b = static_cast<int>((x[k] - origin[k]) * inv[k]);
    return std::clamp(b, 0, nb[k] - 1);
  };
  const std::size_t nbins = static_cast<std::size_t>(nb[0]) * nb[1] * nb[2];
  std::vector<int> bin_of(n), bin_start(nbins + 1, 0), bin_items(n);
#pragma omp parallel for schedule(static) num_threads(nthreads)
  for (long i = 0; i < ln; ++i) {
    const Vec3& x = p.x[static_cast<std::size_t>(i)];
    bin_of[static_cast<std::size_t>(i)] =
        (bin_coord(x, 2) * nb[1] + bin_coord(x, 1)) * nb[0] + bin_coord(x, 0);
  }
  for (std::size_t i = 0; i < n; ++i) ++bin_start[static_cast<std::size_t>(bin_of[i]) + 1];
  for (std::size_t b = 0; b < nbins; ++b) bin_start[b + 1] += bin_start[b];
  {
    std::vector<int> fill(bin_start.begin(), bin_start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) bin_items[fill[bin_of[i]]++] = static_cast<int>(i);
  }

  const bool any_periodic = domain.periodic(0) || domain.periodic(1) || domain.periodic(2);
  // Partners are found bin by bin (one stencil per bin) and stored per particle; every particle
  // lives in one bin, so the bins can be searched in parallel. The per-particle buffers are kept
  // between builds: their capacity makes later builds allocation-free.
  if (found_.size() < n) found_.resize(n);
  if (!any_periodic) {
    // Positions and radii in bin order: the bins x-1, x, x+1 of a row are consecutive bin
    // indices, so their particles are one contiguous run, and a stencil is 9 runs.
    bin_x_.resize(n);
    bin_r_.resize(n);
#pragma omp parallel for schedule(static) num_threads(nthreads)
    for (long s = 0; s < ln; ++s) {
      const auto i = static_cast<std::size_t>(bin_items[static_cast<std::size_t>(s)]);
      bin_x_[static_cast<std::size_t>(s)] = p.x[i];
      bin_r_[static_cast<std::size_t>(s)] = p.radius[i];
    }
    const Vec3* bx = bin_x_.data();
    const double* br = bin_r_.data();
    const int* items = bin_items.data();
    const int* start = bin_start.data();
#pragma omp parallel for schedule(dynamic, 16) num_threads(nthreads)
    for (std::size_t b = 0; b < nbins; ++b) {
      if (start[b] == start[b + 1]) continue;
      const int bx0 = static_cast<int>(b % nb[0]), by = static_cast<int>((b / nb[0]) % nb[1]);
      const int bz = static_cast<int>(b / (static_cast<std::size_t>(nb[0]) * nb[1]));
      // The 9 runs [first bin of the row, one past its last bin), rows in (z, y) order.
      int runs[9][2];
      int nruns = 0;
      const int x_lo = std::max(bx0 - 1, 0), x_hi = std::min(bx0 + 1, nb[0] - 1);
      for (int z = std::max(bz - 1, 0); z <= std::min(bz + 1, nb[2] - 1); ++z)
        for (int y = std::max(by - 1, 0); y <= std::min(by + 1, nb[1] - 1); ++y) {
          const int row = (z * nb[1] + y) * nb[0];
          runs[nruns][0] = start[row + x_lo];
          runs[nruns][1] = start[row + x_hi + 1];
          ++nruns;
        }
      int candidates = 0;
      for (int r = 0; r < nruns; ++r) candidates += runs[r][1] - runs[r][0];
      // Partners are first written to a local buffer without branching on the two coin-flip
      // tests (index order and distance): every candidate is stored, and the count advances
      // only for a partner. A dense bin's stencil may exceed the buffer; then partners go
      // to the vector one by one.
      int buf[kScanBuffer];
      const bool fits = candidates <= kScanBuffer;
      for (int s = start[b]; s < start[b + 1]; ++s) {
        const int i = items[s];
        const Vec3 xi = bx[s];
        const double ri = br[s] + skin;
        auto& out = found_[static_cast<std::size_t>(i)];
        out.clear();
        int m = 0;
        for (int r = 0; r < nruns; ++r)
          for (int t = runs[r][0]; t < runs[r][1]; ++t) {
            const int j = items[t];
            const Vec3 d = xi - bx[t];
            const double reach = ri + br[t];
            const bool take = (j > i) & (norm2(d) < reach * reach);
            if (fits) {
              buf[m] = j;
              m += take;
            } else if (take) {
              out.push_back(j);
            }
          }
        if (fits) out.assign(buf, buf + m);
        // Sorted partners give a deterministic pair order and allow the merge below.
        std::sort(out.begin(), out.end());
      }
    }
  } else {  // periodic: the stencil wraps, and bins may repeat when a dimension is short
#pragma omp parallel num_threads(nthreads)
    {
      std::vector<int> stencil;
      stencil.reserve(27);
#pragma omp for schedule(dynamic, 16)
      for (std::size_t b = 0; b < nbins; ++b) {
        if (bin_start[b] == bin_start[b + 1]) continue;
        const int bx = static_cast<int>(b % nb[0]), by = static_cast<int>((b / nb[0]) % nb[1]);
        const int bz = static_cast<int>(b / (static_cast<std::size_t>(nb[0]) * nb[1]));
        stencil.clear();
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              int c[3] = {bx + dx, by + dy, bz + dz};
              bool ok = true;
              for (int k = 0; k < 3 && ok; ++k) {
                if (c[k] < 0 || c[k] >= nb[k]) {
                  if (domain.periodic(k)) c[k] = (c[k] + nb[k]) % nb[k];
                  else ok = false;
                }
              }
              if (!ok) continue;
              const int cb = (c[2] * nb[1] + c[1]) * nb[0] + c[0];
              if (std::find(stencil.begin(), stencil.end(), cb) == stencil.end())
                stencil.push_back(cb);
            }
        for (int s = bin_start[b]; s < bin_start[b + 1]; ++s) {
          const int i = bin_items[s];
          const Vec3 xi = p.x[i];
          const double ri = p.radius[i] + skin;
          auto& out = found_[i];
          out.clear();
          for (int cb : stencil) {
            for (int t = bin_start[cb]; t < bin_start[cb + 1]; ++t) {
              const int j = bin_items[t];
              if (j <= i) continue;
              const Vec3 d = domain.minimum_image(xi - p.x[j]);
              const double reach = ri + p.radius[j];
              if (norm2(d) < reach * reach) out.push_back(j);
            }
          }
          std::sort(out.begin(), out.end());
        }
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) first[i + 1] = first[i] + static_cast<int>(found_[i].size());
  // Sized without clearing: every entry is written below, in parallel.
  partner.resize(static_cast<std::size_t>(first[n]));
  history.resize(partner.size() * kHistorySize);
#pragma omp parallel for schedule(static) num_threads(nthreads)
  for (long i = 0; i < ln; ++i) {
    std::copy(found_[i].begin(), found_[i].end(), partner.begin() + first[i]);
    std::fill(history.begin() + static_cast<std::ptrdiff_t>(first[i]) * kHistorySize,
              history.begin() + static_cast<std::ptrdiff_t>(first[i + 1]) * kHistorySize, 0.0);
    if (!same_order) {
      const int oi = old_index[static_cast<std::size_t>(i)];
      if (oi < 0) continue;
      for (int k = first[i]; k < first[i + 1]; ++k) {
        const int oj = old_index[static_cast<std::size_t>(partner[k])];
        if (oj < 0) continue;
        // The old list holds the pair under the lower of its two old indices.
        const int lo = std::min(oi, oj), hi = std::max(oi, oj);
        const auto from = old_partner.begin() + old_first[lo];
        const auto to = old_partner.begin() + old_first[lo + 1];
        const auto at = std::lower_bound(from, to, hi);
        if (at == to || *at != hi) continue;
        const double* h =
            &old_history[static_cast<std::size_t>(at - old_partner.begin()) * kHistorySize];
        if (!any_nonzero(h)) continue;
        // History is oriented from the first to the second particle of the pair.
        const double sign = oi < oj ? 1.0 : -1.0;
        double* to_h = &history[static_cast<std::size_t>(k) * kHistorySize];
        for (int c = 0; c < kHistorySize; ++c) to_h[c] = sign * h[c];
      }
      continue;
    }
    if (static_cast<std::size_t>(i) + 1 >= old_first.size()) continue;
    int a = old_first[i];
    const int a_end = old_first[i + 1];
    for (int k = first[i]; k < first[i + 1] && a < a_end; ++k) {
      while (a < a_end && old_partner[a] < partner[k]) ++a;
      if (a < a_end && old_partner[a] == partner[k])
        std::copy_n(&old_history[static_cast<std::size_t>(a) * kHistorySize], kHistorySize,
                    &history[static_cast<std::size_t>(k) * kHistorySize]);
    }
  }
  mark_touching(p, domain, nthreads);
}

void NeighborList::mark_touching(const Particles& p, const Domain& domain, int nthreads) {
  const std::size_t n = first.size() - 1;
  touching.resize(partner.size());
  // LIGGGHTS 3.8 keeps the history of a pair across a neighbour build only when the pair
  // touches at the positions of the build, which are those of the force evaluation that
  // follows it in the same step; whether it touched at the previous evaluation does not matter.
  // So a contact that still touched at the last evaluation but is open at the build loses its
  // spring, and a pair that opened earlier (its history kept while it stayed in the list) and
  // touches again at the build resumes it. Found by running LIGGGHTS on two particles with
  // builds forced (neigh_modify every N check no) at the first step a contact is open (history
  // dropped), one step earlier (kept), and at the first step of a contact after a flight
  // (kept), in a run and at the set-up of a run; tests/liggghts/test_contact_parity.py,
  // case pair_bounce_build_at_open_and_close, keeps this. The touch test is the one of the pair
  // loop, so the next evaluation finds exactly the contacts marked here.
  const bool any_periodic = domain.periodic(0) || domain.periodic(1) || domain.periodic(2);
  // The work of a particle in a step: its contacts dominate (pairs apart cost little), the
  // integrator and the other per-particle loops cost about half a contact.
  std::vector<long> work(n + 1, 0);
  const long ln = static_cast<long>(n);
#pragma omp parallel for schedule(static) num_threads(nthreads)
  for (long i = 0; i < ln; ++i) {
    long contacts = 0;
    const Vec3 xi = p.x[static_cast<std::size_t>(i)];
    const double ri = p.radius[static_cast<std::size_t>(i)];
    for (int k = first[i]; k < first[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(partner[k]);
      Vec3 d = xi - p.x[j];
      if (any_periodic) d = domain.minimum_image(d);
      const double radsum = ri + p.radius[j];
      const bool touches = norm2(d) < radsum * radsum;
      touching[static_cast<std::size_t>(k)] = touches ? 1 : 0;
      contacts += touches ? 1 : 0;
      if (!touches)
        std::fill_n(&history[static_cast<std::size_t>(k) * kHistorySize], kHistorySize, 0.0);
    }
    work[static_cast<std::size_t>(i) + 1] = 1 + 2 * contacts;
  }
  for (std::size_t i = 0; i < n; ++i) work[i + 1] += work[i];
  partition_.balance(work, nthreads);
}

}  // namespace dem
