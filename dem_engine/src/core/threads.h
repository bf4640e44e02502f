#pragma once
#include <omp.h>

#include <algorithm>
#include <cstddef>

namespace dem {

// Threads worth using for a loop over n particles: below ~1000 particles per thread the
// fork/join cost exceeds the work, so small systems run on one thread.
inline int worker_threads(std::size_t n) {
  const int by_size = static_cast<int>(n / 1000) + 1;
  return std::max(1, std::min(omp_get_max_threads(), by_size));
}

}  // namespace dem
