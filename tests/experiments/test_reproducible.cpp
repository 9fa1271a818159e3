#include <gtest/gtest.h>

#include "experiments/runner/run.hpp"

namespace icd::runner {
namespace {

// The same scene with a budget counted in sphere tests must give bitwise
// identical results run after run (wall-clock budgets cannot: they depend on
// the machine). Small enough budget that queries are interrupted.
TEST(Reproducible, SameSceneSameTestBudgetGivesIdenticalFrames) {
  const char* text = R"({
    "frames": 25, "frame_rate": 60,
    "objects": [
      {"name": "a", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 2, "cells": 4},
       "position": [-0.11, 0.01, 0], "velocity": [0.8, 0, 0], "material": {"young": 5e5}},
      {"name": "b", "primitive": {"type": "box", "extent": [0.2, 0.15, 0.2], "subdivisions": 2, "cells": 4},
       "position": [0.11, 0, 0], "rotation_deg": [10, 20, 30], "velocity": [-0.8, 0, 0],
       "material": {"young": 5e5}}
    ],
    "collision": {"budget_tests": 40, "stiffness": 2000, "layered": true},
    "output": {"csv": false}
  })";
  const Scene scene = parse_scene(parse_json(text, "repro"), "repro", ".");
  std::vector<std::vector<FrameMetrics>> runs(2);
  std::vector<MatX3d> final_positions;
  for (auto& frames : runs) {
    World world = make_world(scene, "", "");
    for (int f = 0; f < scene.frames; ++f) frames.push_back(world.step());
    final_positions.push_back(world.objects()[0].positions);
  }
  int interrupted = 0;
  for (int f = 0; f < scene.frames; ++f) {
    const FrameMetrics &a = runs[0][f], &b = runs[1][f];
    EXPECT_EQ(a.pair_list, b.pair_list) << f;
    EXPECT_EQ(a.collision_list, b.collision_list) << f;
    EXPECT_EQ(a.tests, b.tests) << f;
    EXPECT_EQ(a.active_pairs, b.active_pairs) << f;
    EXPECT_EQ(a.max_penetration, b.max_penetration) << f;  // bitwise
    EXPECT_EQ(a.contact_force, b.contact_force) << f;
    EXPECT_EQ(a.energy, b.energy) << f;
    interrupted += a.interrupted;
  }
  EXPECT_GT(interrupted, 0);  // the budget did cut queries short
  EXPECT_TRUE((final_positions[0].array() == final_positions[1].array()).all());
}

}  // namespace
}  // namespace icd::runner
