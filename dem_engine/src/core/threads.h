#pragma once
#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace dem {

// Threads worth using for a loop over n particles: below ~1000 particles per thread the
// fork/join cost exceeds the work, so small systems run on one thread.
inline int worker_threads(std::size_t n) {
  const int by_size = static_cast<int>(n / 1000) + 1;
  return std::max(1, std::min(omp_get_max_threads(), by_size));
}

// Particles [begin, end) owned by one thread.
struct ParticleShare {
  std::size_t begin = 0, end = 0;
};

// How the particles are split between the threads of a time step: contiguous shares of about
// equal work, the same for every per-particle loop, so that a thread keeps touching the same
// particles (and cache lines) from one loop to the next. Moving cache lines between cores,
// slow on shared hosts, would otherwise cost more than the loops themselves.
class ParticlePartition {
 public:
  // Balances the shares for `team` threads: weight_prefix[i] is the summed work of particles
  // 0 .. i-1 (n + 1 entries, non-decreasing).
  void balance(const std::vector<long>& weight_prefix, int team) {
    const std::size_t n = weight_prefix.empty() ? 0 : weight_prefix.size() - 1;
    n_ = n;
    bounds_.assign(static_cast<std::size_t>(team) + 1, n);
    bounds_[0] = 0;
    const double total = n > 0 ? static_cast<double>(weight_prefix[n]) : 0.0;
    for (int t = 1; t < team; ++t) {
      const double target = total * t / team;
      bounds_[static_cast<std::size_t>(t)] = static_cast<std::size_t>(
          std::lower_bound(weight_prefix.begin(), weight_prefix.begin() + static_cast<long>(n),
                           target) -
          weight_prefix.begin());
    }
  }

  // The share of thread t of a team of `team` over n particles; equal counts when the
  // partition was balanced for another particle count or team.
  ParticleShare share(std::size_t n, int t, int team) const {
    if (n == n_ && static_cast<std::size_t>(team) + 1 == bounds_.size())
      return {bounds_[static_cast<std::size_t>(t)], bounds_[static_cast<std::size_t>(t) + 1]};
    return {n * static_cast<std::size_t>(t) / static_cast<std::size_t>(team),
            n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(team)};
  }

  // Runs body(begin, end) for every thread's share of n particles, on worker_threads(n) threads.
  template <class Body>
  void for_each(std::size_t n, Body&& body) const {
#pragma omp parallel num_threads(worker_threads(n))
    {
      const ParticleShare s = share(n, omp_get_thread_num(), omp_get_num_threads());
      body(s.begin, s.end);
    }
  }

 private:
  std::vector<std::size_t> bounds_;
  std::size_t n_ = 0;
};

}  // namespace dem
