#include "core/neighbor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace dem {

bool NeighborList::due(const Particles& p, long steps_since_build) const {
  if (forced_ || x_at_build_.size() != p.size()) return true;
  if (steps_since_build < delay || steps_since_build % std::max(every, 1) != 0) return false;
  if (!check) return true;
  const double limit2 = 0.25 * skin * skin;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i)
    if (norm2(p.x[i] - x_at_build_[i]) > limit2) return true;
  return false;
}

namespace {

struct OldContact {
  std::uint64_t key;
  bool swapped;  // stored as (larger tag, smaller tag)
  std::array<double, kHistorySize> hist;
};

std::uint64_t pair_key(std::int64_t a, std::int64_t b, bool& swapped) {
  swapped = a > b;
  const auto lo = static_cast<std::uint64_t>(swapped ? b : a);
  const auto hi = static_cast<std::uint64_t>(swapped ? a : b);
  return (lo << 32) ^ hi;
}

}  // namespace

void NeighborList::build(const Particles& p, const Domain& domain) {
  // Collect the contacts with history from the previous list, keyed by tags.
  std::vector<OldContact> old;
  for (std::size_t i = 0; i + 1 < first.size(); ++i) {
    for (int k = first[i]; k < first[i + 1]; ++k) {
      const double* h = &history[static_cast<std::size_t>(k) * kHistorySize];
      bool any = false;
      for (int c = 0; c < kHistorySize; ++c) any = any || h[c] != 0.0;
      if (!any) continue;
      OldContact oc;
      oc.key = pair_key(tags_at_build_[i], tags_at_build_[partner[k]], oc.swapped);
      std::copy(h, h + kHistorySize, oc.hist.begin());
      old.push_back(oc);
    }
  }
  std::sort(old.begin(), old.end(),
            [](const OldContact& a, const OldContact& b) { return a.key < b.key; });

  const std::size_t n = p.size();
  first.assign(n + 1, 0);
  partner.clear();
  history.clear();
  x_at_build_ = p.x;
  tags_at_build_ = p.tag;
  forced_ = false;
  ++builds_;
  if (n == 0) return;

  double rmax = 0.0;
  Vec3 lo = p.x[0], hi = p.x[0];
  for (std::size_t i = 0; i < n; ++i) {
    rmax = std::max(rmax, p.radius[i]);
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p.x[i][k]);
      hi[k] = std::max(hi[k], p.x[i][k]);
    }
  }
  const double cutoff = 2.0 * rmax + skin;
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
  for (std::size_t i = 0; i < n; ++i) {
    const int b = (bin_coord(p.x[i], 2) * nb[1] + bin_coord(p.x[i], 1)) * nb[0] +
                  bin_coord(p.x[i], 0);
    bin_of[i] = b;
    ++bin_start[b + 1];
  }
  for (std::size_t b = 0; b < nbins; ++b) bin_start[b + 1] += bin_start[b];
  {
    std::vector<int> fill(bin_start.begin(), bin_start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) bin_items[fill[bin_of[i]]++] = static_cast<int>(i);
  }

  const bool any_periodic = domain.periodic(0) || domain.periodic(1) || domain.periodic(2);
  std::vector<int> stencil;
  stencil.reserve(27);
  for (std::size_t i = 0; i < n; ++i) {
    const int b = bin_of[i];
    const int bx = b % nb[0], by = (b / nb[0]) % nb[1], bz = b / (nb[0] * nb[1]);
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
          if (std::find(stencil.begin(), stencil.end(), cb) == stencil.end()) stencil.push_back(cb);
        }
    for (int cb : stencil) {
      for (int s = bin_start[cb]; s < bin_start[cb + 1]; ++s) {
        const int j = bin_items[s];
        if (static_cast<std::size_t>(j) <= i) continue;
        Vec3 d = p.x[i] - p.x[j];
        if (any_periodic) d = domain.minimum_image(d);
        const double reach = p.radius[i] + p.radius[j] + skin;
        if (norm2(d) < reach * reach) partner.push_back(j);
      }
    }
    // Sorted partners give a deterministic pair order independent of the stencil order.
    std::sort(partner.begin() + first[i], partner.end());
    first[i + 1] = static_cast<int>(partner.size());
  }

  history.assign(partner.size() * kHistorySize, 0.0);
  if (old.empty()) return;
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = first[i]; k < first[i + 1]; ++k) {
      bool swapped = false;
      const std::uint64_t key = pair_key(p.tag[i], p.tag[partner[k]], swapped);
      auto it = std::lower_bound(old.begin(), old.end(), key,
                                 [](const OldContact& a, std::uint64_t kk) { return a.key < kk; });
      if (it == old.end() || it->key != key) continue;
      // History is oriented from the first to the second particle of the pair.
      const double sign = swapped == it->swapped ? 1.0 : -1.0;
      double* h = &history[static_cast<std::size_t>(k) * kHistorySize];
      for (int c = 0; c < kHistorySize; ++c) h[c] = sign * it->hist[c];
    }
  }
}

}  // namespace dem
