#include <icd/collision/cycle_clock.hpp>

#include <chrono>

#if defined(__x86_64__)
#include <x86intrin.h>
#endif

namespace icd::collision {

bool has_cycle_counter() {
#if defined(__x86_64__)
  return true;
#else
  return false;
#endif
}

uint64_t read_cycle_counter() {
#if defined(__x86_64__)
  return __rdtsc();
#else
  return 0;
#endif
}

double cycle_counter_hz() {
  static const double hz = [] {
    if (!has_cycle_counter()) return 0.0;
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    const uint64_t c0 = read_cycle_counter();
    while (clock::now() - t0 < std::chrono::milliseconds(20)) {
    }
    const auto t1 = clock::now();
    const uint64_t c1 = read_cycle_counter();
    return double(c1 - c0) / std::chrono::duration<double>(t1 - t0).count();
  }();
  return hz;
}

}  // namespace icd::collision
