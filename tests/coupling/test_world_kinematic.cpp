// Scripted kinematic motion (coupling/kinematic_motion.hpp): a keyframed
// rigid object is where the analytic interpolation puts it, a probe driven
// into a deformable ball pushes it, and set_kinematic_pose reaches its pose
// in one frame.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/world.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

WorldObject sphere(const char* name, double radius, const Eigen::Vector3d& centre, ObjectKind kind) {
  PrimitiveSpec p;
  p.radius = radius;
  p.subdivisions = 2;
  p.cells = 5;
  WorldObject o;
  o.setup.name = name;
  o.setup.kind = kind;
  o.setup.material.model = fem::MaterialModel::StableNeoHookean;
  o.setup.material.young = 5e5;
  o.setup.damping.alpha = 0.5;
  o.asset = make_primitive_asset(p, 3);
  place_asset(o.asset, {0, centre, {0, 0, 0}});
  return o;
}

WorldSettings deterministic() {
  WorldSettings s;
  s.collision.query.budget_seconds = std::numeric_limits<double>::infinity();
  s.collision.query.budget_tests = 200000;
  return s;
}

TEST(KinematicMotion, KeyframedObjectFollowsTheAnalyticInterpolation) {
  const Eigen::Vector3d c0(0.3, -0.2, 0.1);
  std::vector<WorldObject> objects;
  objects.push_back(sphere("probe", 0.05, c0, ObjectKind::Rigid));
  const MatX3d rest = objects[0].asset.coarse.V;
  std::vector<Keyframe> keys(3);
  keys[0].t = 0;
  keys[0].position = c0;
  keys[1].t = 0.5;
  keys[1].position = c0 + Eigen::Vector3d(0.2, 0, 0);
  keys[1].rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  keys[2].t = 1.0;
  keys[2].position = c0 + Eigen::Vector3d(0.2, 0.1, 0);
  keys[2].rotation = keys[1].rotation;
  objects[0].setup.motion = KeyframeMotion(keys, c0).function();
  World world(std::move(objects), deterministic());
  // Independent: a z rotation by an angle linear in time (slerp about one
  // axis), the centre linear in time, both held after t = 1.
  const auto expected = [&](double t) {
    const double s1 = std::clamp(t / 0.5, 0.0, 1.0), s2 = std::clamp((t - 0.5) / 0.5, 0.0, 1.0);
    const Eigen::Vector3d c = c0 + Eigen::Vector3d(0.2 * s1, 0.1 * s2, 0);
    const double a = s1 * M_PI / 2;
    MatX3d x(rest.rows(), 3);
    for (int v = 0; v < rest.rows(); ++v) {
      const Eigen::Vector3d d = rest.row(v).transpose() - c0;
      x.row(v) << c.x() + std::cos(a) * d.x() - std::sin(a) * d.y(),
          c.y() + std::sin(a) * d.x() + std::cos(a) * d.y(), c.z() + d.z();
    }
    return x;
  };
  EXPECT_LT((world.objects()[0].positions - expected(0)).cwiseAbs().maxCoeff(), 1e-12);
  int checked = 0;
  for (int f = 1; f <= 80; ++f) {
    world.step();
    if (f % 7 == 0 || f == 30 || f == 60 || f == 80) {
      EXPECT_LT((world.objects()[0].positions - expected(f / 60.0)).cwiseAbs().maxCoeff(), 1e-9)
          << "frame " << f;
      ++checked;
    }
  }
  EXPECT_GE(checked, 10);
}

// A probe keyframed into a free deformable ball (no gravity): contact forces
// appear and push the ball away along the probe's motion.
TEST(KinematicMotion, KeyframedProbePushesADeformableBall) {
  std::vector<WorldObject> objects;
  objects.push_back(sphere("ball", 0.1, Eigen::Vector3d::Zero(), ObjectKind::Deformable));
  objects.push_back(sphere("probe", 0.04, Eigen::Vector3d(0.3, 0, 0), ObjectKind::Rigid));
  std::vector<Keyframe> keys(2);
  keys[0].t = 0;
  keys[0].position = {0.3, 0, 0};
  keys[1].t = 0.5;
  keys[1].position = {0.1, 0, 0};  // 4 cm into the ball's rest surface
  objects[1].setup.motion = KeyframeMotion(keys, keys[0].position).function();
  World world(std::move(objects), deterministic());
  double force = 0;
  for (int f = 0; f < 45; ++f) force = std::max(force, world.step().contact_force);
  const RuntimeObject& ball = world.objects()[0];
  const Eigen::Vector3d centre = ball.positions.colwise().mean();
  const Eigen::Vector3d v = ball.sim->velocities().colwise().mean();
  RecordProperty("max_contact_force_N", std::to_string(force));
  RecordProperty("ball_centre_x_mm", std::to_string(centre.x() * 1e3));
  EXPECT_GT(force, 0.1);
  EXPECT_LT(centre.x(), -0.005);  // pushed at least 5 mm in -x
  EXPECT_LT(v.x(), 0);
  EXPECT_LT(std::abs(centre.y()) + std::abs(centre.z()), 0.2 * std::abs(centre.x()));
}

TEST(KinematicMotion, SetKinematicPoseReachesThePoseInOneFrame) {
  std::vector<WorldObject> objects;
  objects.push_back(sphere("ball", 0.1, Eigen::Vector3d(1, 0, 0), ObjectKind::Deformable));
  objects.push_back(sphere("probe", 0.05, Eigen::Vector3d::Zero(), ObjectKind::Rigid));
  World world(std::move(objects), deterministic());
  const MatX3d rest = world.objects()[1].rest;
  RigidPose pose;
  pose.translation = {0, 0.1, 0.05};
  pose.rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX());
  world.set_kinematic_pose(1, pose);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const MatX3d target = (rest * r.transpose()).rowwise() + pose.translation.transpose();
  EXPECT_GT((world.objects()[1].positions - target).cwiseAbs().maxCoeff(), 0.01);  // not yet
  world.step();
  EXPECT_LT((world.objects()[1].positions - target).cwiseAbs().maxCoeff(), 1e-12);
  world.step();  // held
  EXPECT_LT((world.objects()[1].positions - target).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_THROW(world.set_kinematic_pose(0, pose), ParameterError);  // deformable
  EXPECT_THROW(world.set_kinematic_pose(5, pose), ParameterError);
  pose.translation.x() = std::nan("");
  EXPECT_THROW(world.set_kinematic_pose(1, pose), ParameterError);
}

TEST(KinematicMotion, KeyframesAreValidated) {
  std::vector<Keyframe> keys(2);
  keys[1].t = 0;
  EXPECT_THROW(KeyframeMotion(keys, Eigen::Vector3d::Zero()), ParameterError);
  keys[1].t = 1;
  keys[1].rotation = Eigen::Quaterniond(0, 0, 0, 0);
  EXPECT_THROW(KeyframeMotion(keys, Eigen::Vector3d::Zero()), ParameterError);
  EXPECT_THROW(KeyframeMotion({}, Eigen::Vector3d::Zero()), ParameterError);
}

}  // namespace
}  // namespace icd::coupling
