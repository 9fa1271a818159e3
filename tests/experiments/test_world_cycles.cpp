#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "experiments/runner/world.hpp"

namespace icd::runner {
namespace {

// Two soft spheres meeting head-on (as in test_head_on.cpp); `collision` is
// spliced into the scene's collision block.
Scene head_on_scene(const std::string& collision) {
  const std::string text = R"({
    "frames": 30, "frame_rate": 60,
    "objects": [
      {"name": "left", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 2, "cells": 5},
       "position": [-0.12, 0, 0], "velocity": [0.6, 0, 0],
       "material": {"young": 5e5, "poisson": 0.3, "density": 1000}, "preprocess": {"tree_depth": 3}},
      {"name": "right", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 2, "cells": 5},
       "position": [0.12, 0, 0], "velocity": [-0.6, 0, 0],
       "material": {"young": 5e5, "poisson": 0.3, "density": 1000}, "preprocess": {"tree_depth": 3}}
    ],
    "collision": {"stiffness": 2000, )" + collision + R"(},
    "output": {"csv": false}
  })";
  return parse_scene(parse_json(text, "head_on"), "head_on", ".");
}

double mean_velocity_x(const RuntimeObject& o) {
  const Eigen::VectorXd& m = o.sim->model().mass();
  return (o.sim->velocities().col(0).dot(m)) / m.sum();
}

// Frames that start apart run as a single cycle (rolled back when the closing
// query finds a contact). Reference: the same scene with every frame cycled.
// The motion must agree (the two differ only in FEM step sizes while apart),
// the single-cycle run must actually have skipped cycles and rolled back at
// first contact.
TEST(WorldCycles, SingleCycleFramesWhileApartMatchFullyCycledFrames) {
  World fast(head_on_scene(R"("budget_tests": 1000000)"), "", "");
  World full(head_on_scene(R"("budget_tests": 1000000, "single_cycle_when_apart": false)"), "", "");
  int single = 0, rollbacks = 0, first_contact_fast = -1, first_contact_full = -1;
  double max_rel_dx = 0;
  for (int f = 0; f < 30; ++f) {
    const FrameMetrics a = fast.step();
    const FrameMetrics b = full.step();
    EXPECT_GT(b.cycles, 1) << "frame " << f;
    EXPECT_EQ(b.rollback, 0);
    single += a.cycles == 1;
    rollbacks += a.rollback;
    if (a.active_pairs > 0 && first_contact_fast < 0) first_contact_fast = f;
    if (b.active_pairs > 0 && first_contact_full < 0) first_contact_full = f;
    const double dx = (fast.objects()[0].positions - full.objects()[0].positions).rowwise().norm().maxCoeff();
    max_rel_dx = std::max(max_rel_dx, dx / 0.1);
  }
  EXPECT_GT(single, 5);
  EXPECT_GE(rollbacks, 1);
  EXPECT_EQ(first_contact_fast, first_contact_full);
  // Both bounce: same rebound speed to within 2%, nodes within 1% of the radius.
  const double va = mean_velocity_x(fast.objects()[0]), vb = mean_velocity_x(full.objects()[0]);
  EXPECT_LT(vb, -0.1);
  EXPECT_NEAR(va, vb, 0.02 * std::abs(vb));
  EXPECT_LT(max_rel_dx, 0.01);
}

// A query interrupted in contact: with on_interrupt = "previous" the response
// uses the pair's last complete answer at the current sphere positions, so
// the force stays close to that of an uninterrupted query; the paper's rule
// ("untested": the PAIRLIST's coarse spheres count as colliding) pushes with
// the much deeper overlap of inner spheres.
TEST(WorldCycles, InterruptedQueryReusesThePreviousCompleteAnswer) {
  const char* unlimited = R"("unlimited": true)";
  World exact(head_on_scene(std::string(unlimited) + R"(, "on_interrupt": "previous")"), "", "");
  World previous(head_on_scene(std::string(unlimited) + R"(, "on_interrupt": "previous")"), "", "");
  World untested(head_on_scene(std::string(unlimited) + R"(, "on_interrupt": "untested")"), "", "");
  // Same deterministic history up to two frames into the contact.
  int f = 0, in_contact = 0;
  for (; f < 30 && in_contact < 2; ++f) {
    const FrameMetrics m = exact.step();
    previous.step();
    untested.step();
    in_contact += m.active_pairs > 0;
  }
  ASSERT_EQ(in_contact, 2) << "no contact within 30 frames";
  // One more frame: exact with no budget; the others with a budget so small
  // (1 ns) that every query stops at its first clock check, right at the top.
  const FrameMetrics e = exact.step();
  const FrameMetrics p = previous.step(1e-9);
  const FrameMetrics u = untested.step(1e-9);
  ASSERT_EQ(e.interrupted, 0);
  ASSERT_EQ(p.interrupted, p.cycles);
  ASSERT_EQ(u.interrupted, u.cycles);
  EXPECT_EQ(p.reused, p.cycles);
  EXPECT_EQ(u.reused, 0);
  ASSERT_GT(e.contact_force, 0);
  EXPECT_NEAR(p.contact_force, e.contact_force, 0.25 * e.contact_force);
  EXPECT_GT(u.max_penetration, 3 * e.max_penetration);
}

}  // namespace
}  // namespace icd::runner
