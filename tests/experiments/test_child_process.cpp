// The runner's child processes (icd-preprocess) and names used as file names.
#include <gtest/gtest.h>

#include <signal.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <icd/mesh/core/error.hpp>
#include "experiments/runner/child_process.hpp"
#include "experiments/runner/run.hpp"

namespace icd::runner {
namespace {

namespace fs = std::filesystem;

TEST(ChildProcess, ArgumentsArriveVerbatimWithoutAShell) {
  const fs::path out = fs::path(::testing::TempDir()) / "icd_child_args.txt";
  fs::remove(out);
  const std::string hostile = "$(touch x) `y` \"z\" 'w' ; | & *";
  const ChildResult r =
      run_child({"/bin/sh", "-c", "printf '%s' \"$1\" > \"$2\"", "sh", hostile, out.string()});
  EXPECT_TRUE(r.ok()) << r.describe({});
  std::ifstream in(out);
  std::string got;
  std::getline(in, got);
  EXPECT_EQ(got, hostile);
  EXPECT_EQ(display_command({"a b", "c"}), "'a b' c");
}

TEST(ChildProcess, ExitStatusAndMissingProgramAreReported) {
  const ChildResult r = run_child({"/bin/sh", "-c", "exit 3"});
  EXPECT_EQ(r.exit_status, 3);
  EXPECT_EQ(r.describe({}), "exited with status 3");
  EXPECT_THROW(run_child({"/nonexistent/icd-preprocess"}), InputError);
}

// A runaway child (the preprocessing of a pathological mesh) is stopped by
// its CPU-time limit, and a sleeping one by its wall-clock limit.
TEST(ChildProcess, LimitsStopARunawayChild) {
  ChildLimits cpu;
  cpu.cpu_seconds = 1;
  auto t0 = std::chrono::steady_clock::now();
  ChildResult r = run_child({"/bin/sh", "-c", "while :; do :; done"}, cpu);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.describe(cpu).find("CPU-time limit of 1 s"), std::string::npos) << r.describe(cpu);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 30);

  ChildLimits wall;
  wall.wall_seconds = 0.5;
  t0 = std::chrono::steady_clock::now();
  r = run_child({"/bin/sh", "-c", "exec sleep 30"}, wall);  // (exec: no orphan holding stdout)
  EXPECT_TRUE(r.timed_out);
  EXPECT_NE(r.describe(wall).find("wall-clock limit"), std::string::npos) << r.describe(wall);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10);

  ChildLimits memory;
  memory.memory_bytes = 256 << 20;  // 256 MiB of address space: 1 GiB cannot be allocated
  EXPECT_TRUE(run_child({"/usr/bin/python3", "-c", "b = bytearray(16 << 20)"}, memory).ok());
  EXPECT_FALSE(run_child({"/usr/bin/python3", "-c",
                          "try:\n  b = bytearray(1 << 30)\nexcept MemoryError:\n  exit(1)"},
                         memory)
                   .ok());
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The options icd-sweep runs its cases with: working directory, stdin from
// /dev/null, stdout and stderr into files (truncated).
TEST(ChildProcess, WorkingDirectoryAndRedirections) {
  const fs::path dir = fs::path(::testing::TempDir()) / "icd_child_cwd";
  fs::remove_all(dir);
  fs::create_directories(dir);
  ChildOptions o;
  o.cwd = dir;
  o.stdout_file = dir / "out.txt";
  o.stderr_file = dir / "err.txt";
  o.stdin_null = true;
  std::ofstream(o.stdout_file) << "old contents, longer than the new ones\n";
  const ChildResult r =
      run_child({"/bin/sh", "-c", "pwd -P; echo to-stderr >&2; cat; echo end"}, {}, o);
  EXPECT_TRUE(r.ok()) << r.describe({});
  EXPECT_EQ(slurp(o.stdout_file), fs::canonical(dir).string() + "\nend\n");  // cat read EOF
  EXPECT_EQ(slurp(o.stderr_file), "to-stderr\n");
  o.cwd = dir / "missing";
  try {
    run_child({"/bin/true"}, {}, o);
    ADD_FAILURE() << "a missing working directory must throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
}

/// Running (a zombie waiting for a reaper that may never come in a container
/// counts as ended).
bool alive(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  if (!std::getline(in, stat)) return false;
  const std::size_t close = stat.rfind(')');
  return close != std::string::npos && close + 2 < stat.size() && stat[close + 2] != 'Z';
}

// With its own process group, a timeout kills the child's children too; the
// stop flag (icd-sweep's SIGTERM) ends it early.
TEST(ChildProcess, ProcessGroupTimeoutAndStop) {
  const fs::path pid_file = fs::path(::testing::TempDir()) / "icd_child_grandchild.pid";
  fs::remove(pid_file);
  ChildLimits wall;
  wall.wall_seconds = 0.5;
  ChildOptions o;
  o.own_process_group = true;
  const ChildResult r = run_child(
      {"/bin/sh", "-c", "sleep 30 & echo $! > \"$1\"; wait", "sh", pid_file.string()}, wall, o);
  EXPECT_TRUE(r.timed_out);
  const pid_t grandchild = std::stoi(slurp(pid_file));
  bool gone = false;
  for (int k = 0; k < 200 && !gone; ++k) {  // reaped by init: up to 2 s
    gone = !alive(grandchild);
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(gone) << "the grandchild " << grandchild << " survived the timeout";
  if (!gone) kill(grandchild, SIGKILL);

  std::atomic<bool> stop{false};
  o.stop = &stop;
  std::thread t([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    stop = true;
  });
  const auto t0 = std::chrono::steady_clock::now();
  const ChildResult s = run_child({"/bin/sh", "-c", "exec sleep 30"}, ChildLimits{0, 0, 0}, o);
  t.join();
  EXPECT_TRUE(s.stopped);
  EXPECT_FALSE(s.timed_out);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10);
}

TEST(FileNames, NamesBecomeOneSafeFileNameComponent) {
  EXPECT_EQ(file_name_from("left"), "left");
  EXPECT_EQ(file_name_from("../../x"), "_._.._x");
  EXPECT_EQ(file_name_from("/tmp/x"), "_tmp_x");
  EXPECT_EQ(file_name_from(".."), "_.");
  EXPECT_EQ(file_name_from(""), "_");
  EXPECT_EQ(file_name_from("a b\n\xC3\xA9"), "a_b___");
  EXPECT_EQ(file_name_from(std::string(300, 'a')).size(), 100u);
}

}  // namespace
}  // namespace icd::runner
