// The runner's child processes (icd-preprocess) and names used as file names.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

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
