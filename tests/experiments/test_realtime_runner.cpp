// Real-time mode through the runner: frames.csv records each frame's
// deadline, whether it was met and the lateness (and whether it was cycled
// on a predicted contact); an impossible deadline
// (FEM alone exceeds it) is said once on stderr, with the figure, and again
// in the run summary.
#include <gtest/gtest.h>

#include <algorithm>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "experiments/runner/scene.hpp"
#include "experiments/runner/run.hpp"

namespace icd::runner {
namespace {

namespace fs = std::filesystem;

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(RealTimeRunner, ImpossibleDeadlineIsSaidOnceAndEveryFrameIsRecorded) {
  const std::string ball =
      R"("primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 1, "cells": 3},)"
      R"( "material": {"model": "stvk", "young": 5e5, "poisson": 0.3, "density": 1000},)"
      R"( "preprocess": {"tree_depth": 2})";
  const std::string text = R"({"name": "rt", "frames": 6, "target_fps": 100000, "objects": [)"
                           R"({"name": "a", "position": [-0.12, 0, 0], "velocity": [0.5, 0, 0], )" +
                           ball + R"(}, {"name": "b", "position": [0.12, 0, 0], "velocity": [-0.5, 0, 0], )" +
                           ball + R"(}], "output": {"csv": true}})";
  const Scene scene = parse_scene(parse_json(text, "rt.json"), "rt.json", ".");
  const fs::path out = fs::path(::testing::TempDir()) / "icd_rt_runner";
  fs::remove_all(out);
  RunOptions o;
  o.out_dir = out;
  o.cache_dir = out / "cache";
  o.tool_dir = out / "tools";
  o.progress = false;
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  o.log = log;
  ::testing::internal::CaptureStderr();
  const std::vector<FrameMetrics> frames = run_scene(scene, o);
  const std::string err = ::testing::internal::GetCapturedStderr();
  std::rewind(log);
  std::string summary;
  for (int c; (c = std::fgetc(log)) != EOF;) summary.push_back(static_cast<char>(c));
  std::fclose(log);
  EXPECT_EQ(count(err, "cannot be met"), 1) << err;
  EXPECT_EQ(count(err, "deadline of 0.01 ms"), 1) << err;
  EXPECT_NE(summary.find("0 of 6 frames met their deadline"), std::string::npos) << summary;
  EXPECT_NE(summary.find("6 frame(s) where FEM alone exceeded the deadline"), std::string::npos)
      << summary;
  // frames.csv: the deadline columns of every frame.
  std::ifstream csv(out / "frames.csv");
  std::string header, line;
  std::getline(csv, header);
  ASSERT_NE(header.find(",deadline,deadline_met,lateness,min_budget_queries,fem_over_deadline"),
            std::string::npos);
  // (by name: later columns may follow)
  std::vector<std::string> names;
  {
    std::stringstream hs(header);
    for (std::string c; std::getline(hs, c, ',');) names.push_back(c);
  }
  const size_t n = static_cast<size_t>(
      std::find(names.begin(), names.end(), "fem_over_deadline") - names.begin() + 1);
  ASSERT_LE(n, names.size());
  // Whether the frame was cycled at once on a predicted contact: the
  // `predicted` column holds FrameMetrics::predicted of each frame.
  const size_t pc =
      static_cast<size_t>(std::find(names.begin(), names.end(), "predicted") - names.begin());
  ASSERT_LT(pc, names.size()) << header;
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    ASSERT_EQ(cells.size(), names.size());
    EXPECT_DOUBLE_EQ(std::stod(cells[n - 5]), 1e-5);  // deadline
    EXPECT_EQ(cells[n - 4], "0");                      // missed
    EXPECT_GT(std::stod(cells[n - 3]), 0);             // late
    EXPECT_EQ(cells[n - 1], "1");                      // FEM alone over it
    ASSERT_LT(static_cast<size_t>(rows), frames.size() + 1);
    EXPECT_EQ(cells[pc], std::to_string(frames[static_cast<size_t>(rows - 1)].predicted));
  }
  EXPECT_EQ(rows, 6);
  EXPECT_EQ(frames.size(), 6u);
}

}  // namespace
}  // namespace icd::runner
