#pragma once
/// A std::chrono clock reading the CPU time of the process, so that a time
/// budget does not depend on how loaded the machine is.
#include <chrono>
#include <ctime>

namespace icd::mesh {

/// Process CPU time (clock_gettime(CLOCK_PROCESS_CPUTIME_ID)): the time all
/// threads of this process have spent on a CPU. Meets the Clock requirements.
struct CpuClock {
  using rep = long long;                                 ///< nanoseconds
  using period = std::nano;                              ///< tick length
  using duration = std::chrono::nanoseconds;             ///< tick count type
  using time_point = std::chrono::time_point<CpuClock>;  ///< CPU time since the process started
  static constexpr bool is_steady = true;                ///< never goes back

  /// The CPU time consumed by the process so far.
  static time_point now() noexcept {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return time_point(duration(static_cast<rep>(ts.tv_sec) * 1000000000LL + ts.tv_nsec));
  }
};

}  // namespace icd::mesh
