#pragma once
/// Running a helper program (icd-preprocess) without a shell: the arguments
/// go to execv as a vector, so no path or option is ever interpreted by a
/// shell, and the child runs under CPU-time, wall-clock and memory limits so
/// that a runaway child cannot hang the runner or exhaust the machine.
#include <cstdint>
#include <string>
#include <vector>

namespace icd::runner {

/// Limits of a child process. 0 means no limit.
struct ChildLimits {
  double cpu_seconds = 3600;       ///< RLIMIT_CPU (the child gets SIGXCPU, then SIGKILL)
  double wall_seconds = 4 * 3600;  ///< killed (SIGKILL) when it runs longer than this
  std::uint64_t memory_bytes = std::uint64_t{16} << 30;  ///< RLIMIT_AS (address space)
};

/// How a child process ended.
struct ChildResult {
  int exit_status = -1;    ///< exit status when it exited normally, else -1
  int signal = 0;          ///< the signal that ended it, else 0
  bool timed_out = false;  ///< killed by the runner after ChildLimits::wall_seconds
  /// For messages: "exited with status 1", "was killed by signal 24
  /// (SIGXCPU: its CPU-time limit of 3600 s was reached)", "was killed after
  /// running longer than its wall-clock limit of 14400 s".
  std::string describe(const ChildLimits& limits) const;
  bool ok() const { return exit_status == 0; }
};

/// Runs `argv[0]` (a path, not searched in PATH) with the arguments `argv`,
/// inheriting stdin/stdout/stderr, under `limits`, and waits for it. Throws
/// icd::InputError when the program cannot be started (naming it and why).
ChildResult run_child(const std::vector<std::string>& argv, const ChildLimits& limits = {});

/// `argv` as one line for messages, each argument quoted when it holds
/// anything but [A-Za-z0-9_./=+-] and raw bytes escaped (\xNN). For display
/// only: nothing runs it.
std::string display_command(const std::vector<std::string>& argv);

}  // namespace icd::runner
