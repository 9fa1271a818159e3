#include <gtest/gtest.h>

#include <cmath>

#include "experiments/runner/run.hpp"
#include "tests/experiments/head_on_scene.hpp"

namespace icd::runner {
namespace {

Eigen::Vector3d momentum(RuntimeObject& o) {
  const Eigen::VectorXd& m = o.sim->model().mass();
  return (o.sim->velocities().transpose() * m);
}

Eigen::Vector3d centre(const RuntimeObject& o) { return o.positions.colwise().mean().transpose(); }

// Two identical soft spheres meet head-on along x. Expected: total momentum
// stays zero (contact forces are equal and opposite, elastic forces sum to
// zero), they bounce apart along x with opposite velocities, the motion stays
// on the x axis (y, z momentum negligible), spheres do not interpenetrate
// deeply, and no energy is created.
TEST(HeadOn, SoftSpheresBounceApartSymmetrically) {
  Scene scene = head_on_scene(R"("budget_tests": 1000000, "layered": true)");
  scene.frames = 40;
  World world = make_world(scene, "", "");
  auto& objs = world.objects();
  const double mass = objs[0].sim->model().mass().sum();
  const double e0 = objs[0].sim->total_energy() + objs[1].sim->total_energy();
  double max_pen = 0;
  int contact_frames = 0;
  for (int f = 0; f < scene.frames; ++f) {
    const FrameMetrics m = world.step();
    max_pen = std::max(max_pen, m.max_penetration);
    contact_frames += m.active_pairs > 0;
    const Eigen::Vector3d p = momentum(objs[0]) + momentum(objs[1]);
    ASSERT_LT(p.norm(), 1e-9 * mass * 0.6) << "frame " << f;
  }
  EXPECT_GT(contact_frames, 0);
  const Eigen::Vector3d v0 = momentum(objs[0]) / mass, v1 = momentum(objs[1]) / mass;
  // Separated and moving apart.
  EXPECT_LT(v0.x(), -0.1);
  EXPECT_GT(v1.x(), 0.1);
  EXPECT_GT(centre(objs[1]).x() - centre(objs[0]).x(), 0.2);
  // Symmetric: equal and opposite, on the axis.
  EXPECT_NEAR(v0.x(), -v1.x(), 1e-9);
  EXPECT_LT(std::hypot(v0.y(), v0.z()), 0.02 * std::abs(v0.x()));
  // Restitution at most 1 (no energy created), and no deep interpenetration.
  EXPECT_LE(std::abs(v0.x()) / 0.6, 1.05);
  EXPECT_LT(max_pen, 0.3 * 0.1);
  const double e1 = objs[0].sim->total_energy() + objs[1].sim->total_energy();
  EXPECT_LT(e1, 1.05 * e0);
}

}  // namespace
}  // namespace icd::runner
