#pragma once
/// Scenes of the reliability programs (issue 9), built as JSON text and read
/// through the runner's own parser so that they obey the scene-file rules.
#include <cstdint>
#include <string>

#include "experiments/runner/scene.hpp"

namespace icd::reliability {

/// Options of the built-in repeated-contact scene.
struct ContactBoxOptions {
  int64_t budget_tests = 2000;  ///< collision budget per pair query, sphere tests
  double speed = 1.0;           ///< initial speed of the ball towards a wall, m/s
  double stiffness = 2000;      ///< penalty stiffness, N/m
  int cells = 4;                ///< coarse cells across the ball
  std::string integrator = "rk4";
};

/// A deformable ball (radius 0.1 m, StVK, undamped) bouncing between two
/// static box walls 0.5 m apart along x: it hits a wall about every
/// 0.3 / speed seconds, forever. Budget counted in sphere tests, so a run is
/// deterministic. Objects: 0 ball, 1 left wall, 2 right wall.
runner::Scene make_contact_box_scene(const ContactBoxOptions& options);

/// Replaces a scene's collision budget by `budget_tests` sphere tests per
/// query (no clock), for runs that must be bitwise reproducible.
void use_test_budget(runner::Scene& scene, int64_t budget_tests);

}  // namespace icd::reliability
