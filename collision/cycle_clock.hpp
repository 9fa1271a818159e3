#pragma once
/// The processor's cycle counter as a cheap clock for budget checks.
#include <cstdint>

namespace icd::collision {

/// True when a constant-rate cycle counter (x86-64 rdtsc) is available.
bool has_cycle_counter();

/// Current cycle counter value (0 when unavailable).
uint64_t read_cycle_counter();

/// Cycle counter ticks per second, measured once (about 20 ms against
/// std::chrono::steady_clock on first call; thread-safe). 0 when unavailable.
double cycle_counter_hz();

}  // namespace icd::collision
