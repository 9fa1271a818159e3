#include "experiments/runner/child_process.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <thread>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/input_file.hpp>

namespace icd::runner {
namespace {

/// What the child reports through the pipe when it cannot exec.
struct StartFailure {
  int stage = 0;  ///< 1 stdin, 2 stdout file, 3 stderr file, 4 working directory, 5 exec
  int error = 0;  ///< errno
};

}  // namespace

std::string ChildResult::describe(const ChildLimits& limits) const {
  if (timed_out)
    return "was killed after running longer than its wall-clock limit of " +
           std::to_string(static_cast<long long>(limits.wall_seconds)) + " s";
  if (stopped) return "was stopped (the caller was interrupted)";
  if (signal == SIGXCPU)
    return "was killed by signal " + std::to_string(signal) + " (SIGXCPU: its CPU-time limit of " +
           std::to_string(static_cast<long long>(std::ceil(limits.cpu_seconds))) +
           " s was reached)";
  if (signal != 0)
    return "was killed by signal " + std::to_string(signal) + " (" + strsignal(signal) + ")";
  return "exited with status " + std::to_string(exit_status);
}

ChildResult run_child(const std::vector<std::string>& argv, const ChildLimits& limits,
                      const ChildOptions& options) {
  if (argv.empty()) throw ParameterError("run_child: no program given");
  // Everything the child needs is prepared before fork(): after it, only
  // async-signal-safe calls (setpgid, open, dup2, chdir, setrlimit, execv,
  // write, _exit).
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const std::string cwd = options.cwd.string(), out_file = options.stdout_file.string(),
                    err_file = options.stderr_file.string();
  int pipe_fd[2];  // reports a start failure (stage, errno) to the parent
  if (pipe2(pipe_fd, O_CLOEXEC) != 0)
    throw InputError("cannot start " + escape_bytes(argv[0]) + ": " + std::strerror(errno));
  const rlim_t cpu =
      limits.cpu_seconds > 0 ? static_cast<rlim_t>(std::ceil(limits.cpu_seconds)) : 0;
  const auto memory = static_cast<rlim_t>(limits.memory_bytes);
  const pid_t pid = fork();
  if (pid < 0) {
    const int e = errno;
    close(pipe_fd[0]);
    close(pipe_fd[1]);
    throw InputError("cannot start " + escape_bytes(argv[0]) + ": " + std::strerror(e));
  }
  if (pid == 0) {
    close(pipe_fd[0]);
    StartFailure f;
    auto redirect = [&](const char* path, int flags, int target, int stage) {
      const int fd = open(path, flags | O_CLOEXEC, 0644);
      if (fd < 0 || dup2(fd, target) < 0) f = {stage, errno};  // (dup2 clears O_CLOEXEC)
    };
    if (options.own_process_group) setpgid(0, 0);
    if (options.stdin_null) redirect("/dev/null", O_RDONLY, 0, 1);
    if (f.stage == 0 && !out_file.empty())
      redirect(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 1, 2);
    if (f.stage == 0 && !err_file.empty())
      redirect(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 2, 3);
    if (f.stage == 0 && !cwd.empty() && chdir(cwd.c_str()) != 0) f = {4, errno};
    if (f.stage == 0) {
      if (cpu > 0) {
        const rlimit r{cpu, cpu + 5};  // SIGXCPU at the soft limit, SIGKILL 5 s later
        (void)setrlimit(RLIMIT_CPU, &r);
      }
      if (memory > 0) {
        const rlimit r{memory, memory};  // may only lower the inherited limit; best effort
        (void)setrlimit(RLIMIT_AS, &r);
      }
      execv(args[0], args.data());
      f = {5, errno};
    }
    (void)!write(pipe_fd[1], &f, sizeof f);
    _exit(127);
  }
  if (options.own_process_group) setpgid(pid, pid);  // (from the parent too: no race with a kill)
  const pid_t target = options.own_process_group ? -pid : pid;
  close(pipe_fd[1]);
  StartFailure failure;
  ssize_t n;
  do {
    n = read(pipe_fd[0], &failure, sizeof failure);
  } while (n < 0 && errno == EINTR);
  close(pipe_fd[0]);
  ChildResult r;
  const auto start = std::chrono::steady_clock::now();
  const bool poll = limits.wall_seconds > 0 || options.stop != nullptr;
  int status = 0;
  for (;;) {
    const pid_t w = waitpid(pid, &status, poll ? WNOHANG : 0);
    if (w == pid) break;
    if (w < 0 && errno != EINTR)
      throw InputError("waiting for " + escape_bytes(argv[0]) + ": " + std::strerror(errno));
    if (w == 0) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!r.timed_out && !r.stopped) {
        if (limits.wall_seconds > 0 && elapsed > limits.wall_seconds) {
          kill(target, SIGKILL);
          r.timed_out = true;
        } else if (options.stop && options.stop->load()) {
          kill(target, SIGKILL);
          r.stopped = true;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  if (options.own_process_group) kill(-pid, SIGKILL);  // grandchildren left behind, if any
  if (n == static_cast<ssize_t>(sizeof failure)) {
    const std::string why = std::strerror(failure.error);
    switch (failure.stage) {
      case 1:
        throw InputError("cannot start " + escape_bytes(argv[0]) + ": /dev/null: " + why);
      case 2:
        throw InputError("cannot start " + escape_bytes(argv[0]) + ": cannot write " +
                         escape_bytes(out_file) + ": " + why);
      case 3:
        throw InputError("cannot start " + escape_bytes(argv[0]) + ": cannot write " +
                         escape_bytes(err_file) + ": " + why);
      case 4:
        throw InputError("cannot start " + escape_bytes(argv[0]) + " in " + escape_bytes(cwd) +
                         ": " + why);
      default:
        throw InputError("cannot run " + escape_bytes(argv[0]) + ": " + why);
    }
  }
  if (WIFEXITED(status)) r.exit_status = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  return r;
}

std::string display_command(const std::vector<std::string>& argv) {
  std::string out;
  for (const std::string& a : argv) {
    if (!out.empty()) out += ' ';
    bool plain = !a.empty();
    for (const char c : a)
      plain = plain && c != '\0' &&
              (std::isalnum(static_cast<unsigned char>(c)) || std::strchr("_./=+-", c));
    if (!plain) out += '\'';  // (appends: GCC 12 warns falsely on "'" + string + "'")
    out += escape_bytes(a, 4096);
    if (!plain) out += '\'';
  }
  return out;
}

}  // namespace icd::runner
