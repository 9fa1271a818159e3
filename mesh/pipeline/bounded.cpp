#include <icd/mesh/pipeline/bounded.hpp>

#include <CGAL/exceptions.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>

namespace icd::mesh {
namespace {

using Clock = std::chrono::steady_clock;

// First byte of a child's answer.
enum Tag : char {
  ok = 'O',
  input_error = 'I',
  parameter_error = 'P',
  out_of_memory = 'M',
  cgal_failure = 'C',
  other_error = 'E'
};

std::string fmt(double x, int precision = 3) {
  std::ostringstream s;
  s.precision(precision);
  s << x;
  return s.str();
}

/// CPU seconds (all threads) and resident MiB of a live process, from /proc.
bool probe(pid_t pid, double& cpu, double& rss_mb) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const auto close = line.rfind(')');  // the command name may contain spaces
  if (close == std::string::npos) return false;
  std::istringstream in(line.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  long long rss_pages = 0;
  for (int i = 3; i <= 24 && in >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
    if (i == 24) rss_pages = std::stoll(field);
  }
  const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
  cpu = static_cast<double>(utime + stime) / tick;
  rss_mb = static_cast<double>(rss_pages) * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1048576.0;
  return true;
}

void write_all(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

/// The child: limits, scratch folder, silent streams, run, answer, _exit.
[[noreturn]] void child(int fd, const StageLimits& limits, const std::string& scratch,
                        const std::function<std::string()>& work) {
  const rlim_t cpu = static_cast<rlim_t>(std::ceil(limits.cpu_seconds));
  rlimit r{cpu, cpu + 5};
  setrlimit(RLIMIT_CPU, &r);
  const rlim_t bytes = static_cast<rlim_t>(limits.memory_mb * 1048576.0);
  r = {bytes, bytes};
  setrlimit(RLIMIT_AS, &r);
  r = {0, 0};
  setrlimit(RLIMIT_CORE, &r);
  if (::chdir(scratch.c_str()) != 0) _exit(3);
  const int null = ::open("/dev/null", O_WRONLY);
  if (null >= 0 && !std::getenv("ICD_STAGE_DEBUG")) {
    ::dup2(null, 1);
    ::dup2(null, 2);
  }
  std::string answer;
  try {
    answer = std::string(1, ok) + work();
  } catch (const ParameterError& e) {
    answer = std::string(1, parameter_error) + e.what();
  } catch (const InputError& e) {
    answer = std::string(1, input_error) + e.what();
  } catch (const std::bad_alloc&) {
    answer = std::string(1, out_of_memory);
  } catch (const CGAL::Failure_exception& e) {
    answer = std::string(1, cgal_failure) + e.what();
  } catch (const std::length_error&) {  // a vector that could not grow
    answer = std::string(1, out_of_memory);
  } catch (const std::exception& e) {
    answer = std::string(1, other_error) + e.what();
  } catch (...) {
    answer = std::string(1, other_error) + "unknown exception";
  }
  write_all(fd, answer);
  ::close(fd);
  _exit(0);
}

}  // namespace

std::string run_bounded(const std::string& stage, const StageLimits& limits,
                        const std::function<std::string()>& work, StageUsage* usage,
                        const HeartbeatFn& heartbeat, const std::string& hint) {
  if (!(limits.cpu_seconds > 0.0) || !(limits.memory_mb > 0.0))
    throw ParameterError("stage limits: cpu_seconds (--time-limit) and memory_mb "
                         "(--memory-limit) must be > 0");
  const auto t0 = Clock::now();
  const std::string tail = hint.empty() ? "" : "; " + hint;
  if (!limits.isolate) {
    const std::clock_t c0 = std::clock();
    std::string out = work();
    if (usage) {
      usage->wall_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
      usage->cpu_seconds = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
      rusage ru{};
      getrusage(RUSAGE_SELF, &ru);
      usage->peak_mb = static_cast<double>(ru.ru_maxrss) / 1024.0;
    }
    return out;
  }

  std::string scratch_template =
      (std::filesystem::temp_directory_path() / "icd-stage-XXXXXX").string();
  if (!::mkdtemp(scratch_template.data()))
    throw InputError("stage " + stage + ": cannot create a scratch folder in " +
                     std::filesystem::temp_directory_path().string());
  const std::string scratch = scratch_template;
  int fds[2];
  if (::pipe(fds) != 0) {
    std::filesystem::remove_all(scratch);
    throw InputError("stage " + stage + ": cannot create a pipe");
  }
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    std::filesystem::remove_all(scratch);
    throw InputError("stage " + stage + ": cannot start a child process");
  }
  if (pid == 0) {
    ::close(fds[0]);
    child(fds[1], limits, scratch, work);
  }
  ::close(fds[1]);

  // Read the answer while the child runs (it blocks once the pipe is full);
  // report progress; stop it when it outgrows the limits (the child's own
  // rlimits are the primary guard; these catch what they cannot, e.g. a
  // process sleeping forever or resident memory beyond the limit).
  std::string answer;
  double last_beat = 0.0, cpu = 0.0, rss = 0.0, peak_seen = 0.0;
  bool killed_wall = false, killed_memory = false;
  const double wall_limit = 10.0 * limits.cpu_seconds + 60.0;
  for (;;) {
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, 200);
    if (ready > 0) {
      char buf[65536];
      const ssize_t n = ::read(fds[0], buf, sizeof buf);
      if (n > 0) {
        answer.append(buf, static_cast<std::size_t>(n));
        continue;
      }
      if (n == 0) break;  // EOF: the child closed its end or ended
    }
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    if (probe(pid, cpu, rss)) {
      peak_seen = std::max(peak_seen, rss);
      if (rss > limits.memory_mb && !killed_memory) {
        killed_memory = true;
        ::kill(pid, SIGKILL);
      }
    }
    if (wall > wall_limit && !killed_wall) {
      killed_wall = true;
      ::kill(pid, SIGKILL);
    }
    if (heartbeat && wall >= 1.0 && wall - last_beat >= (last_beat == 0.0 ? 1.0 : 5.0)) {
      last_beat = wall;
      heartbeat("running: " + fmt(cpu) + " s cpu, " + fmt(rss, 4) + " MB, " + fmt(wall) +
                " s wall");
    }
  }
  ::close(fds[0]);
  int status = 0;
  rusage ru{};
  while (::wait4(pid, &status, 0, &ru) < 0 && errno == EINTR) {
  }
  std::filesystem::remove_all(scratch);
  const double child_cpu = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
                           1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  const double peak_mb = std::max(peak_seen, static_cast<double>(ru.ru_maxrss) / 1024.0);
  if (usage) {
    usage->wall_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    usage->cpu_seconds = child_cpu;
    usage->peak_mb = peak_mb;
  }

  const std::string cpu_msg = "stage '" + stage + "' exceeded its CPU-time limit of " +
                              fmt(limits.cpu_seconds) + " s (option --time-limit)" + tail;
  const std::string mem_msg = "stage '" + stage + "' exceeded its memory limit of " +
                              fmt(limits.memory_mb, 6) + " MB (option --memory-limit)" + tail;
  if (WIFSIGNALED(status) || answer.empty()) {
    const int sig = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    if (sig == SIGXCPU || child_cpu >= limits.cpu_seconds)
      throw StageError(StageError::Kind::cpu_limit, cpu_msg);
    if (killed_memory || peak_mb >= 0.95 * limits.memory_mb)
      throw StageError(StageError::Kind::memory_limit, mem_msg);
    if (killed_wall)
      throw StageError(StageError::Kind::cpu_limit,
                       "stage '" + stage + "' did not finish within " + fmt(wall_limit) +
                           " s of wall time (10 x the CPU-time limit of --time-limit + 60 s)" +
                           tail);
    throw StageError(StageError::Kind::crashed,
                     "stage '" + stage + "' crashed" +
                         (sig ? " (signal " + std::to_string(sig) + ")" : " (no result)") + tail);
  }
  const char tag = answer[0];
  std::string body = answer.substr(1);
  switch (tag) {
    case ok:
      return body;
    case input_error:
      throw InputError(body);
    case parameter_error:
      throw ParameterError(body);
    case out_of_memory:
      throw StageError(StageError::Kind::memory_limit, mem_msg);
    case cgal_failure:
      // CGAL's assertion text names its source lines, not the user's input:
      // only its kind is reported.
      throw StageError(StageError::Kind::internal,
                       "stage '" + stage + "' failed inside CGAL (an internal check did not hold" +
                           (peak_mb >= 0.9 * limits.memory_mb ? ", close to the memory limit" : "") +
                           ")" + tail +
                           (std::getenv("ICD_STAGE_DEBUG") ? " [ICD_STAGE_DEBUG: " + body + "]" : ""));
    default:
      throw StageError(StageError::Kind::internal, "stage '" + stage + "' failed: " + body + tail);
  }
}

}  // namespace icd::mesh
