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

void set_limit(int resource, rlim_t value) {
  const rlimit r{value, value};
  (void)setrlimit(resource, &r);  // may only lower the inherited limit; best effort
}

}  // namespace

std::string ChildResult::describe(const ChildLimits& limits) const {
  if (timed_out)
    return "was killed after running longer than its wall-clock limit of " +
           std::to_string(static_cast<long long>(limits.wall_seconds)) + " s";
  if (signal == SIGXCPU)
    return "was killed by signal " + std::to_string(signal) + " (SIGXCPU: its CPU-time limit of " +
           std::to_string(static_cast<long long>(std::ceil(limits.cpu_seconds))) +
           " s was reached)";
  if (signal != 0)
    return "was killed by signal " + std::to_string(signal) + " (" + strsignal(signal) + ")";
  return "exited with status " + std::to_string(exit_status);
}

ChildResult run_child(const std::vector<std::string>& argv, const ChildLimits& limits) {
  if (argv.empty()) throw ParameterError("run_child: no program given");
  // Everything the child needs is prepared before fork(): after it, only
  // async-signal-safe calls (setrlimit, execv, write, _exit).
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int pipe_fd[2];  // reports an exec failure's errno to the parent
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
    if (cpu > 0) {
      const rlimit r{cpu, cpu + 5};  // SIGXCPU at the soft limit, SIGKILL 5 s later
      (void)setrlimit(RLIMIT_CPU, &r);
    }
    if (memory > 0) set_limit(RLIMIT_AS, memory);
    execv(args[0], args.data());
    const int e = errno;
    (void)!write(pipe_fd[1], &e, sizeof e);
    _exit(127);
  }
  close(pipe_fd[1]);
  int exec_errno = 0;
  ssize_t n;
  do {
    n = read(pipe_fd[0], &exec_errno, sizeof exec_errno);
  } while (n < 0 && errno == EINTR);
  close(pipe_fd[0]);
  ChildResult r;
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  for (;;) {
    const pid_t w = waitpid(pid, &status, limits.wall_seconds > 0 ? WNOHANG : 0);
    if (w == pid) break;
    if (w < 0 && errno != EINTR)
      throw InputError("waiting for " + escape_bytes(argv[0]) + ": " + std::strerror(errno));
    if (w == 0) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (elapsed > limits.wall_seconds && !r.timed_out) {
        kill(pid, SIGKILL);
        r.timed_out = true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  if (n == static_cast<ssize_t>(sizeof exec_errno))
    throw InputError("cannot run " + escape_bytes(argv[0]) + ": " + std::strerror(exec_errno));
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
