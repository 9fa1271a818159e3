#pragma once
/// The one process spawner of the application layer: the scene runner runs
/// icd-preprocess with it, icd-sweep runs every case and setup command with
/// it. The arguments go to execv as a vector, so no path or option is ever
/// interpreted by a shell, and the child runs under CPU-time, wall-clock and
/// memory limits so that a runaway child cannot hang the caller or exhaust
/// the machine. Optionally: its own process group (a timeout or a stop then
/// kills its children too), a working directory, stdin from /dev/null and
/// stdout/stderr redirected into files.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace icd::runner {

/// Limits of a child process. 0 means no limit.
struct ChildLimits {
  double cpu_seconds = 3600;       ///< RLIMIT_CPU (the child gets SIGXCPU, then SIGKILL 5 s later)
  double wall_seconds = 4 * 3600;  ///< killed (SIGKILL) when it runs longer than this
  std::uint64_t memory_bytes = std::uint64_t{16} << 30;  ///< RLIMIT_AS (address space)
};

/// Where and how the child runs (the defaults inherit everything).
struct ChildOptions {
  std::filesystem::path cwd;  ///< working directory (empty: the caller's)
  std::filesystem::path
      stdout_file;  ///< stdout redirected into this file, truncated (empty: inherited)
  std::filesystem::path stderr_file;  ///< stderr likewise
  bool stdin_null = false;            ///< stdin from /dev/null instead of the caller's
  /// The child leads its own process group; the wall-clock limit and `stop`
  /// kill the whole group, and so does the end of the child (grandchildren
  /// left behind are not left running).
  bool own_process_group = false;
  /// Polled while the child runs: when it becomes true the child (its group)
  /// is killed and ChildResult::stopped is set (e.g. the caller got SIGTERM).
  const std::atomic<bool>* stop = nullptr;
};

/// How a child process ended.
struct ChildResult {
  int exit_status = -1;    ///< exit status when it exited normally, else -1
  int signal = 0;          ///< the signal that ended it, else 0
  bool timed_out = false;  ///< killed by the runner after ChildLimits::wall_seconds
  bool stopped = false;    ///< killed because ChildOptions::stop became true
  /// For messages: "exited with status 1", "was killed by signal 24
  /// (SIGXCPU: its CPU-time limit of 3600 s was reached)", "was killed after
  /// running longer than its wall-clock limit of 14400 s".
  std::string describe(const ChildLimits& limits) const;
  bool ok() const { return exit_status == 0; }
};

/// Runs `argv[0]` (a path, not searched in PATH) with the arguments `argv`
/// under `limits` and `options`, and waits for it. Throws icd::InputError
/// when the program cannot be started (naming it and why: a missing program,
/// an output file or working directory that cannot be opened).
ChildResult run_child(const std::vector<std::string>& argv, const ChildLimits& limits = {},
                      const ChildOptions& options = {});

/// `argv` as one line for messages, each argument quoted when it holds
/// anything but [A-Za-z0-9_./=+-] and raw bytes escaped (\xNN). For display
/// only: nothing runs it.
std::string display_command(const std::vector<std::string>& argv);

}  // namespace icd::runner
