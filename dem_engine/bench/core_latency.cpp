// Round trip of one cache line between two cores (ns), a few samples in a row. Two threads
// pinned to cores A and B take turns to write a shared counter; every turn moves the line
// once each way. On shared virtual machines the figure can change by a factor of several
// while the host moves the virtual CPUs, and every multi-threaded time step pays it at each
// barrier and for each particle whose data crosses between threads.
//
// Usage: dem_core_latency [CORE_A CORE_B [SAMPLES]]   (defaults 0 1 5)
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

namespace {

bool pin_to(int core) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(core, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

double round_trip_ns(int core_a, int core_b, long turns) {
  alignas(64) std::atomic<long> counter{0};
  std::thread partner([&] {
    pin_to(core_b);
    for (long i = 0; i < turns; ++i) {
      while (counter.load(std::memory_order_acquire) != 2 * i + 1) {
      }
      counter.store(2 * i + 2, std::memory_order_release);
    }
  });
  pin_to(core_a);
  const auto start = std::chrono::steady_clock::now();
  for (long i = 0; i < turns; ++i) {
    counter.store(2 * i + 1, std::memory_order_release);
    while (counter.load(std::memory_order_acquire) != 2 * i + 2) {
    }
  }
  const auto stop = std::chrono::steady_clock::now();
  partner.join();
  return std::chrono::duration<double, std::nano>(stop - start).count() / static_cast<double>(turns);
}

}  // namespace

int main(int argc, char** argv) {
  const int core_a = argc > 2 ? std::atoi(argv[1]) : 0;
  const int core_b = argc > 2 ? std::atoi(argv[2]) : 1;
  const int samples = argc > 3 ? std::atoi(argv[3]) : 5;
  if (std::thread::hardware_concurrency() < 2 || samples < 1) {
    std::fprintf(stderr, "ERROR: needs two cores and at least one sample\n");
    return 1;
  }
  if (!pin_to(core_a)) {
    std::fprintf(stderr, "ERROR: cannot run on core %d\n", core_a);
    return 1;
  }
  for (int s = 0; s < samples; ++s) std::printf("%.1f\n", round_trip_ns(core_a, core_b, 100000));
  return 0;
}
