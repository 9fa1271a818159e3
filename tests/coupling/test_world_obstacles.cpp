// Static analytic obstacles (coupling/obstacle.hpp): a ball dropped on a
// plane or a thin box under gravity stays on it, within 1 mm, never ends on
// the far side, and comes to rest without gaining energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <icd/coupling/link_evaluator.hpp>
#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/world.hpp>

namespace icd::coupling {
namespace {

WorldObject ball(const Eigen::Vector3d& centre) {
  PrimitiveSpec p;
  p.radius = 0.1;
  p.subdivisions = 2;
  p.cells = 5;
  WorldObject o;
  o.setup.name = "ball";
  o.setup.material.model = fem::MaterialModel::StableNeoHookean;
  o.setup.material.young = 5e5;
  o.setup.damping.alpha = 0.5;
  o.asset = make_primitive_asset(p, 3);
  place_asset(o.asset, {0, centre, {0, 0, 0}});
  return o;
}

WorldObject ball(double z) { return ball(Eigen::Vector3d(0, 0, z)); }

struct Drop {
  double lowest = 0;       // lowest dense vertex above the obstacle's top, m
  double kinetic = 0;      // kinetic energy at the end, J
  double e0 = 0, e_max = 0;
};

Drop drop(const Obstacle& obstacle, double top, double g, double z0, int frames) {
  WorldSettings s;
  s.gravity = {0, 0, -g};
  s.obstacles.push_back(obstacle);
  std::vector<WorldObject> objects;
  objects.push_back(ball(z0));
  World world(std::move(objects), s);
  Drop d;
  for (int f = 0; f < frames; ++f) {
    const FrameMetrics m = world.step();
    if (f == 0) d.e0 = m.energy;
    d.e_max = std::max(d.e_max, m.energy);
    if (std::getenv("ICD_TEST_VERBOSE"))
      std::printf("frame %d energy %.6f cycles %d obstacle_vertices %d depth %.3g support %d\n", f,
                  m.energy, m.cycles, m.obstacle_vertices, m.obstacle_depth,
                  static_cast<int>(world.objects()[0].obstacle_support.size() > 0));
  }
  const RuntimeObject& o = world.objects()[0];
  LinkEvaluator links(o.asset.links);
  MatX3d dense(o.asset.links.num_links(), 3);
  links.apply(o.positions, dense);
  d.lowest = dense.col(2).minCoeff() - top;
  d.kinetic = o.sim->model().kinetic_energy(o.sim->velocities());
  return d;
}

Obstacle plane_at(double z) {
  Obstacle p;
  p.point = {0, 0, z};
  p.normal = {0, 0, 1};
  return p;
}

Obstacle thin_box() {  // 2 cm thick, top at z = 0.01
  Obstacle b;
  b.type = Obstacle::Type::Box;
  b.half_extents = {0.5, 0.5, 0.01};
  return b;
}

TEST(Obstacles, BallStaysOnAThinBoxUnderGravity) {
  const Drop d = drop(thin_box(), 0.01, 9.81, 0.112, 90);
  EXPECT_NEAR(d.lowest, 0.0, 1e-3);
}

// The ball lands 2 mm below its start and stays on the plane; it comes to
// rest: the mechanical energy at every frame end never exceeds its value
// after the first frame, and the kinetic energy ends below 0.1 % of it.
// (Before the support of resting nodes and the energy balance of the
// projection: e_max / e0 = 1.14, kinetic 0.8 % of e0.) One drop for both.
TEST(Obstacles, BallStaysOnAPlaneUnderGravityAndRestingContactGainsNoEnergy) {
  const Drop d = drop(plane_at(0.01), 0.01, 9.81, 0.112, 90);
  EXPECT_NEAR(d.lowest, 0.0, 1e-3);
  EXPECT_LE(d.e_max, d.e0 * (1 + 1e-9));
  EXPECT_LT(d.kinetic, 1e-3 * d.e0);
}

// 1000 m/s^2 (the ball squashes under its own weight): it stays on top of
// the thin box. A short run (each frame needs ~140 cycles); the long drop is
// in experiments (stability_sweep).
TEST(Obstacles, ThinBoxHoldsUnderAThousandG) {
  const Drop d = drop(thin_box(), 0.01, 1000, 0.115, 6);
  EXPECT_GT(d.lowest, -1e-3);  // never through the box
  EXPECT_LT(d.lowest, 1e-3);   // and on it
  EXPECT_LE(d.e_max, d.e0 * (1 + 1e-9));
}

TEST(Obstacles, PlaneHoldsUnderAThousandG) {
  const Drop d = drop(plane_at(0.01), 0.01, 1000, 0.115, 3);  // lands in frame 1
  EXPECT_GT(d.lowest, -1e-3);
  EXPECT_LT(d.lowest, 1e-3);
  EXPECT_LE(d.e_max, d.e0 * (1 + 1e-9));
}

// Two planes tilted 25 degrees each way form a trough (one tilted plane
// alone would let the frictionless ball slide forever). The ball falls off
// centre onto one slope, slides into the trough and comes to rest (Rayleigh
// mass damping), no dense vertex ever more than 1 mm below either plane,
// and the mechanical energy never above its value after the first frame.
TEST(Obstacles, BallComesToRestInATroughOfTiltedPlanes) {
  const double a = 25 * M_PI / 180;
  WorldSettings s;
  s.gravity = {0, 0, -9.81};
  Obstacle left, right;
  left.normal = {std::sin(a), 0, std::cos(a)};
  right.normal = {-std::sin(a), 0, std::cos(a)};
  s.obstacles = {left, right};
  std::vector<WorldObject> objects;
  objects.push_back(ball(Eigen::Vector3d(0.05, 0, 0.2)));  // off centre: lands on one slope
  objects[0].setup.damping.alpha = 2;  // Rayleigh mass damping, 1/s: the ball settles in ~3 s
  World world(std::move(objects), s);
  const RuntimeObject& o = world.objects()[0];
  LinkEvaluator links(o.asset.links);
  MatX3d dense(o.asset.links.num_links(), 3);
  double lowest = std::numeric_limits<double>::infinity(), e0 = 0, e_max = 0, kinetic_max = 0;
  int frames = 0;
  for (; frames < 240; ++frames) {
    const FrameMetrics m = world.step();
    if (frames == 0) e0 = m.energy;
    e_max = std::max(e_max, m.energy);
    links.apply(o.positions, dense);
    for (const Obstacle& p : {left, right})
      for (int v = 0; v < dense.rows(); ++v)
        lowest = std::min(lowest, p.normal.normalized().dot(dense.row(v).transpose()));
    kinetic_max = std::max(kinetic_max, o.sim->model().kinetic_energy(o.sim->velocities()));
    if (frames % 20 == 0 && std::getenv("ICD_TEST_VERBOSE"))
      std::printf("frame %d energy %.6f kinetic %.6f lowest %.3g mm x %.4f\n", frames, m.energy,
                  o.sim->model().kinetic_energy(o.sim->velocities()), lowest * 1e3,
                  o.positions.col(0).mean());
  }
  const double kinetic = o.sim->model().kinetic_energy(o.sim->velocities());
  const Eigen::Vector3d centre = o.positions.colwise().mean();
  RecordProperty("lowest_mm", std::to_string(lowest * 1e3));
  RecordProperty("e_max_over_e0", std::to_string(e_max / e0));
  EXPECT_GT(lowest, -1e-3);
  EXPECT_GT(kinetic_max, 0.05);            // it did fall and slide
  // and came to rest: below 3 % of the peak kinetic energy after 4 s.
  EXPECT_LT(kinetic, 0.03 * kinetic_max);
  EXPECT_NEAR(centre.x(), 0, 0.01);        // at the bottom of the trough
  EXPECT_LE(e_max, e0 * (1 + 1e-9));
}

// Only the dense vertices that may be near an obstacle are tested (a bound
// from the coarse nodes and the link lengths, World::obstacle_layer): a ball
// thrown along a floor into a corner of a tilted wall, with a far plane that
// never comes near, runs bitwise the same trajectory as testing every
// vertex against every obstacle, while the tested layer stays a fraction of
// the surface.
TEST(Obstacles, CullingFarVerticesGivesTheSameTrajectoryBitwise) {
  WorldSettings s;
  s.gravity = {0, 0, -9.81};
  Obstacle floor = thin_box();
  floor.half_extents = {1, 1, 0.01};
  Obstacle wall;
  wall.type = Obstacle::Type::Box;
  wall.point = {0.22, 0.05, 0.2};
  wall.half_extents = {0.02, 0.3, 0.2};
  wall.axes = Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Obstacle far = plane_at(-5);
  s.obstacles = {floor, far, wall};
  const auto make = [&](bool cull) {
    WorldSettings w = s;
    w.obstacle_cull = cull;
    std::vector<WorldObject> objects;
    objects.push_back(ball(Eigen::Vector3d(0.06, 0, 0.112)));
    objects[0].setup.velocity = {1.5, 0.3, 0};
    return World(std::move(objects), w);
  };
  World culled = make(true), every = make(false);
  const int links = culled.objects()[0].asset.links.num_links();
  size_t widest = 0;
  int touching = 0;
  double reach = -1;
  for (int f = 0; f < 10; ++f) {
    const FrameMetrics a = culled.step(), b = every.step();
    const RuntimeObject& oa = culled.objects()[0];
    const RuntimeObject& ob = every.objects()[0];
    ASSERT_EQ(a.cycles, b.cycles) << "frame " << f;
    ASSERT_EQ(a.obstacle_vertices, b.obstacle_vertices) << "frame " << f;
    ASSERT_EQ(a.obstacle_depth, b.obstacle_depth) << "frame " << f;
    ASSERT_EQ(a.energy, b.energy) << "frame " << f;
    ASSERT_TRUE((oa.positions.array() == ob.positions.array()).all()) << "frame " << f;
    ASSERT_TRUE((oa.sim->velocities().array() == ob.sim->velocities().array()).all()) << "frame " << f;
    widest = std::max(widest, oa.obstacle_layer.size());
    touching += a.obstacle_depth > 0;
    reach = std::max(reach, oa.positions.col(0).maxCoeff());
  }
  EXPECT_GT(touching, 0);                          // it did touch the obstacles
  EXPECT_GT(reach, 0.19);  // and reached the wall (its nodes start below x = 0.16)
  EXPECT_LT(widest, static_cast<size_t>(links) / 2);  // a layer, not the whole surface
  EXPECT_EQ(every.objects()[0].obstacle_layer.size(), static_cast<size_t>(links));
}

// The cycles near an obstacle come from how fast the surface approaches it
// (World::obstacle_approach), not from how fast its nodes move: a ball
// sliding along a frictionless floor at 3 m/s keeps the 1 ms cycles (17 per
// frame; the node speed, 3 m/s x 16.7 ms / 1 mm, would ask for 51), while a
// ball thrown down at the thin box at 10 m/s gets at least its approach per
// 1 mm step (167 cycles) and never passes into it by more than 1 mm.
struct Throw {
  int min_cycles_near = 1 << 30, max_cycles_near = 0;  // frames with the ball near the obstacle
  double lowest = std::numeric_limits<double>::infinity();  // over frame ends, above the top, m
  double depth = 0;  // deepest vertex found inside before its projection, m
};
Throw throw_ball(const Eigen::Vector3d& velocity, int frames) {
  WorldSettings s;
  s.gravity = {0, 0, -9.81};
  Obstacle floor = thin_box();
  floor.half_extents = {5, 5, 0.01};
  s.obstacles.push_back(floor);
  std::vector<WorldObject> objects;
  objects.push_back(ball(0.112));  // lowest dense vertex ~2 mm above the top
  objects[0].setup.velocity = velocity;
  World world(std::move(objects), s);
  const RuntimeObject& o = world.objects()[0];
  LinkEvaluator links(o.asset.links);
  MatX3d dense(o.asset.links.num_links(), 3);
  Throw t;
  for (int f = 0; f < frames; ++f) {
    const FrameMetrics m = world.step();
    if (o.near_obstacle) {
      t.min_cycles_near = std::min(t.min_cycles_near, m.cycles_motion);
      t.max_cycles_near = std::max(t.max_cycles_near, m.cycles_motion);
    }
    links.apply(o.positions, dense);
    t.lowest = std::min(t.lowest, dense.col(2).minCoeff() - 0.01);
    t.depth = std::max(t.depth, m.obstacle_depth);
    if (std::getenv("ICD_TEST_VERBOSE"))
      std::printf("frame %d cycles %d motion %d depth %.3g lowest %.3g\n", f, m.cycles,
                  m.cycles_motion, m.obstacle_depth, dense.col(2).minCoeff() - 0.01);
  }
  return t;
}

TEST(Obstacles, SlidingAlongTheFloorAsksNoMoreCyclesThanResting) {
  const Throw t = throw_ball({3, 0, 0}, 8);
  EXPECT_GT(t.max_cycles_near, 0);     // it came near the floor
  EXPECT_LE(t.max_cycles_near, 20);    // the 1 ms cycles (17) and gravity, not 51
  EXPECT_GT(t.lowest, -1e-3);
  EXPECT_LT(t.lowest, 1e-3);           // and it rests on it
}

TEST(Obstacles, FastApproachGetsItsCyclesAndDoesNotSinkIn) {
  const Throw t = throw_ball({0, 0, -10}, 2);
  EXPECT_GE(t.max_cycles_near, 167);   // 10 m/s x 16.7 ms / 1 mm
  EXPECT_GT(t.lowest, -1e-3);
  EXPECT_LT(t.depth, 2e-3);            // found inside by at most about one step
}

TEST(Obstacles, SignedDistanceOfPlaneAndBox) {
  Obstacle p = plane_at(0);
  p.normal = {0, 0, 2};
  validate(p, "p");
  EXPECT_NEAR(p.signed_distance({1, 2, 3}), 3, 1e-15);
  const Obstacle b = thin_box();
  Eigen::Vector3d n;
  EXPECT_NEAR(b.signed_distance({0.1, 0.2, 0.004}, &n), -0.006, 1e-15);
  EXPECT_EQ(n, Eigen::Vector3d(0, 0, 1));
  EXPECT_NEAR(b.signed_distance({0.1, 0.2, -0.008}, &n), -0.002, 1e-15);
  EXPECT_EQ(n, Eigen::Vector3d(0, 0, -1));
  EXPECT_NEAR(b.signed_distance({0.5 + 3e-3, 0.5 + 4e-3, 0}), 5e-3, 1e-12);
  EXPECT_LE(b.lower_bound({-1, -1, -1}, {1, 1, 1}), 0);
  EXPECT_GT(b.lower_bound({-1, -1, 0.02}, {1, 1, 1}), 0);
  Obstacle bad = plane_at(0);
  bad.normal.setZero();
  EXPECT_THROW(validate(bad, "obstacles[0]"), std::exception);
}

}  // namespace
}  // namespace icd::coupling
