// Real-time frames: objects advanced on several threads (bitwise identical
// results), per-object FEM stepping, and the real-time scheduler (deadline,
// minimum collision budget, the impossible-deadline message).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/world.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

WorldObject ball(const std::string& name, const Eigen::Vector3d& x, const Eigen::Vector3d& v,
                 double young = 5e5, int cells = 5) {
  PrimitiveSpec p;
  p.radius = 0.1;
  p.subdivisions = 2;
  p.cells = cells;
  WorldObject o;
  o.setup.name = name;
  o.setup.material.young = young;
  o.setup.velocity = v;
  o.asset = make_primitive_asset(p, 3);
  place_asset(o.asset, {0, x, {0, 0, 0}});
  return o;
}

// Deterministic queries (a test budget): a run depends on nothing but its input.
WorldSettings deterministic(int threads) {
  WorldSettings s;
  s.collision.query.budget_tests = 1000000;
  s.collision.query.budget_seconds = std::numeric_limits<double>::infinity();
  s.collision.contact.stiffness = 2000;
  s.threads = threads;
  return s;
}

std::vector<WorldObject> head_on() {
  std::vector<WorldObject> v;
  v.push_back(ball("left", {-0.12, 0, 0}, {0.6, 0, 0}));
  v.push_back(ball("right", {0.12, 0, 0}, {-0.6, 0, 0}));
  return v;
}

// Five balls thrown at each other inside a static box, under gravity: many
// pairs (broad phase), repeated contacts, obstacle projection.
std::vector<WorldObject> crowd() {
  std::vector<WorldObject> v;
  v.push_back(ball("a", {-0.25, 0, 0.1}, {1.0, 0.2, 0}));
  v.push_back(ball("b", {0.25, 0.02, 0.1}, {-1.0, 0, 0}));
  v.push_back(ball("c", {0, 0.25, 0.05}, {0.1, -1.0, 0}, 1e6));
  v.push_back(ball("d", {0, -0.25, 0.12}, {0, 0.9, 0.1}, 3e5, 4));
  v.push_back(ball("e", {0.02, 0.01, 0.35}, {0, 0, -0.5}));
  return v;
}

WorldSettings with_box(WorldSettings s) {
  s.gravity = {0, 0, -9.81};
  Obstacle floor;
  floor.type = Obstacle::Type::Box;
  floor.point = {0, 0, -0.25};
  floor.half_extents = {1, 1, 0.1};
  s.obstacles.push_back(floor);
  return s;
}

// Runs both worlds frame by frame and requires every coarse position and
// velocity of every object to be bitwise equal after every frame.
void expect_bitwise_equal(World& a, World& b, int frames, int* contact_frames) {
  for (int f = 0; f < frames; ++f) {
    const FrameMetrics ma = a.step();
    const FrameMetrics mb = b.step();
    *contact_frames += ma.active_pairs > 0;
    ASSERT_EQ(ma.substeps, mb.substeps) << "frame " << f;
    ASSERT_EQ(ma.cycles, mb.cycles) << "frame " << f;
    ASSERT_EQ(ma.tests, mb.tests) << "frame " << f;
    for (size_t i = 0; i < a.objects().size(); ++i) {
      const RuntimeObject& oa = a.objects()[i];
      const RuntimeObject& ob = b.objects()[i];
      // Exact comparison on purpose: the threads must not change a bit.
      ASSERT_TRUE((oa.positions.array() == ob.positions.array()).all())
          << "frame " << f << " object " << oa.setup.name << " max |dx| "
          << (oa.positions - ob.positions).cwiseAbs().maxCoeff();
      if (oa.sim) {
        ASSERT_TRUE((oa.sim->velocities().array() == ob.sim->velocities().array()).all())
            << "frame " << f << " object " << oa.setup.name;
      }
    }
  }
}

TEST(WorldRealTime, TwoObjectsAreBitwiseIdenticalFor1And2Threads) {
  World one(head_on(), deterministic(1));
  World two(head_on(), deterministic(2));
  EXPECT_EQ(one.threads(), 1);
  EXPECT_EQ(two.threads(), 2);
  int contact_frames = 0;
  expect_bitwise_equal(one, two, 30, &contact_frames);
  EXPECT_GT(contact_frames, 0);  // the run went through a contact
}

TEST(WorldRealTime, ManyObjectsInABoxAreBitwiseIdenticalFor1And2And3Threads) {
  World one(crowd(), with_box(deterministic(1)));
  World two(crowd(), with_box(deterministic(2)));
  World three(crowd(), with_box(deterministic(3)));
  EXPECT_TRUE(one.plan().broad_phase);
  int contact_frames = 0, ignored = 0;
  expect_bitwise_equal(one, two, 25, &contact_frames);
  EXPECT_GT(contact_frames, 0);
  World one_again(crowd(), with_box(deterministic(1)));
  expect_bitwise_equal(one_again, three, 25, &ignored);
}

TEST(WorldRealTime, OneObjectSplitsItsForceLoopAndStaysBitwiseIdentical) {
  std::vector<WorldObject> a, b;
  a.push_back(ball("solo", {0, 0, 0}, {0, 0, -1}));
  b.push_back(ball("solo", {0, 0, 0}, {0, 0, -1}));
  World one(std::move(a), with_box(deterministic(1)));
  World two(std::move(b), with_box(deterministic(2)));
  EXPECT_EQ(two.objects()[0].sim->model().elastic().options().num_threads, 2);
  int ignored = 0;
  expect_bitwise_equal(one, two, 20, &ignored);
}

// Two objects of the same mesh and density, one 100 times stiffer, far
// apart: the largest eigenfrequency scales with sqrt(E) (linear elasticity,
// same geometry, no damping), so the stiff object's stable step is 10 times
// shorter. Each must keep its own: the soft one takes ~10 times fewer sub-steps.
TEST(WorldRealTime, EachObjectSubStepsAtItsOwnStableStep) {
  std::vector<WorldObject> v;
  v.push_back(ball("soft", {-1, 0, 0}, {0.3, 0, 0}, 5e5));
  v.push_back(ball("stiff", {1, 0, 0}, {-0.3, 0, 0}, 5e7));
  for (WorldObject& o : v) o.setup.damping = {};
  WorldSettings s = deterministic(2);
  s.frame_rate = 5;  // long frames: enough sub-steps that rounding stays small
  World world(std::move(v), s);
  for (int f = 0; f < 3; ++f) {
    const FrameMetrics m = world.step();
    const RuntimeObject& soft = world.objects()[0];
    const RuntimeObject& stiff = world.objects()[1];
    ASSERT_EQ(m.cycles, 1);  // apart: one cycle per frame
    ASSERT_GE(soft.substeps, 20);
    EXPECT_EQ(m.substeps, soft.substeps + stiff.substeps);
    const double ratio = static_cast<double>(stiff.substeps) / soft.substeps;
    EXPECT_NEAR(ratio, std::sqrt(100.0), 0.1 * std::sqrt(100.0)) << "frame " << f;
    EXPECT_NEAR(soft.step / stiff.step, std::sqrt(100.0), 0.1 * std::sqrt(100.0));
    // Each step is below its own object's stable limit (estimated for that object).
    EXPECT_LE(soft.step, soft.sim->stable_step_limit());
    EXPECT_LE(stiff.step, stiff.sim->stable_step_limit());
  }
}

// A deadline already gone before collision starts (10 us for a frame whose
// FEM takes milliseconds): every query still gets the stated minimum budget,
// large enough here that no query is interrupted.
TEST(WorldRealTime, MinimumCollisionBudgetIsHonouredWhenTheFrameIsLate) {
  WorldSettings s;
  s.collision.contact.stiffness = 2000;
  s.target_fps = 1e5;
  s.min_query_budget = 10;  // s: every query completes
  World world(head_on(), s);
  int contact_frames = 0;
  for (int f = 0; f < 30; ++f) {
    const FrameMetrics m = world.step();
    EXPECT_DOUBLE_EQ(m.deadline, 1e-5);
    EXPECT_EQ(m.deadline_met, 0);
    EXPECT_GT(m.lateness, 0);
    EXPECT_NEAR(m.lateness, m.wall - m.deadline, 1e-12);
    EXPECT_EQ(m.budget, s.min_query_budget) << "frame " << f;
    EXPECT_GT(m.min_budget_queries, 0);
    EXPECT_EQ(m.interrupted, 0) << "frame " << f;
    contact_frames += m.active_pairs > 0;
  }
  EXPECT_GT(contact_frames, 0);
}

// A generous deadline (1 s per frame): met, no lateness, the last query's
// budget is what is left of the frame (more than the minimum), no warning.
TEST(WorldRealTime, GenerousDeadlineIsMetWithTheRestOfTheFrameForCollision) {
  WorldSettings s;
  s.collision.contact.stiffness = 2000;
  s.target_fps = 1;
  World world(head_on(), s);
  for (int f = 0; f < 5; ++f) {
    const FrameMetrics m = world.step();
    EXPECT_EQ(m.deadline_met, 1);
    EXPECT_EQ(m.lateness, 0);
    EXPECT_GT(m.budget, s.min_query_budget);
    EXPECT_EQ(m.fem_over_deadline, 0);
    EXPECT_TRUE(m.deadline_warning.empty());
  }
}

TEST(WorldRealTime, ImpossibleDeadlineIsReportedOnceWithTheFigure) {
  WorldSettings s;
  s.collision.contact.stiffness = 2000;
  s.target_fps = 1e5;  // 10 us: FEM alone takes longer
  World world(head_on(), s);
  int warnings = 0;
  for (int f = 0; f < 8; ++f) {
    const FrameMetrics m = world.step();
    EXPECT_EQ(m.fem_over_deadline, 1);
    if (!m.deadline_warning.empty()) {
      ++warnings;
      EXPECT_EQ(f, 0);
      EXPECT_NE(m.deadline_warning.find("deadline of 0.01 ms"), std::string::npos)
          << m.deadline_warning;
      EXPECT_NE(m.deadline_warning.find("FEM"), std::string::npos);
      EXPECT_NE(m.deadline_warning.find("sub-steps"), std::string::npos);
    }
  }
  EXPECT_EQ(warnings, 1);
  // Outside real-time mode: no deadline at all.
  World plain(head_on(), deterministic(1));
  const FrameMetrics m = plain.step();
  EXPECT_EQ(m.deadline_met, -1);
  EXPECT_EQ(m.deadline, 0);
  EXPECT_TRUE(m.deadline_warning.empty());
}

// A deformable ball spinning at 10 rad/s (no gravity, a far partner so its
// tree is updated every frame) turns ~190 degrees in 20 frames. Both update
// rules measure node displacements from the rest nodes: in the rest frame a
// rotation by theta reads as displacements of ~theta x the distance to the
// centre, and the spheres inflated with the angle (before: a dragon tipped
// over by the floor of many_objects, its root sphere from 9.5 to 14 cm in 4
// frames). Updated in the co-rotated frame, a (nearly) rigid spin keeps
// every radius, and the root keeps enclosing the coarse nodes.
TEST(WorldRealTime, SpinningObjectKeepsItsSphereRadii) {
  for (const auto mode :
       {collision::SphereUpdateMode::PaperRatio, collision::SphereUpdateMode::DisplacementBound}) {
    std::vector<WorldObject> v;
    v.push_back(ball("spin", {0, 0, 0}, {0, 0, 0}));
    v.push_back(ball("far", {5, 0, 0}, {0, 0, 0}));
    WorldSettings s = deterministic(1);
    s.collision.update.mode = mode;
    World world(std::move(v), s);
    RuntimeObject& o = world.objects()[0];
    const Eigen::RowVector3d c = o.positions.colwise().mean();
    const Eigen::Vector3d omega(0, 0, 10);  // rad/s
    MatX3d vel(o.positions.rows(), 3);
    for (int n = 0; n < vel.rows(); ++n)
      vel.row(n) = omega.cross((o.positions.row(n) - c).transpose()).transpose();
    o.sim->set_velocities(vel);
    world.step();
    const std::vector<collision::Sphere> first = o.asset.spheres.spheres;
    for (int f = 1; f < 20; ++f) world.step();
    // It did turn: a node's angle about the centre changed by > 150 degrees.
    const Eigen::RowVector3d x0 = o.rest.row(0) - o.rest.colwise().mean();
    const Eigen::RowVector3d x1 = o.positions.row(0) - o.positions.colwise().mean();
    const double turned = std::abs(std::remainder(
        std::atan2(x1.y(), x1.x()) - std::atan2(x0.y(), x0.x()), 2 * M_PI));
    ASSERT_GT(turned, 150 * M_PI / 180) << "mode " << static_cast<int>(mode);
    double worst = 0;
    for (size_t k = 0; k < first.size(); ++k)
      worst = std::max(worst, o.asset.spheres.spheres[k].r / first[k].r);
    EXPECT_LT(worst, 1.05) << "mode " << static_cast<int>(mode);
    const collision::Sphere& root = o.asset.spheres.spheres[0];
    for (int n = 0; n < o.positions.rows(); ++n)
      EXPECT_LE((o.positions.row(n).transpose() - root.center()).norm(), root.r * (1 + 1e-9));
  }
}

// many_objects reduced (an unstable penalty there blew an object up two
// frames after its first contact): two balls and a cube, the cube's coarse
// mesh finer than the balls' (lighter nodes), thrown at each other in a box
// under gravity for 1 s, through repeated contacts with each other, the
// floor and the walls. No health-check failure, the energy never above its
// start (the contact and the obstacles are passive) and the surfaces never
// deeper in each other than a leaf radius.
TEST(WorldRealTime, ThreeObjectsInABoxRunASecondOfRepeatedContacts) {
  // The material of many_objects: inversion-safe, E = 2e5 Pa, light damping.
  const auto soft = [](WorldObject o) {
    o.setup.material.model = fem::MaterialModel::StableNeoHookean;
    o.setup.material.young = 2e5;
    o.setup.damping.alpha = 0.5;
    return o;
  };
  std::vector<WorldObject> v;
  v.push_back(soft(ball("a", {-0.2, 0, -0.02}, {0.6, 0.1, 0})));
  v.push_back(soft(ball("b", {0.2, 0.03, 0.0}, {-0.6, 0, 0.2})));
  WorldObject cube;
  PrimitiveSpec box;
  box.type = "box";
  box.extent = {0.14, 0.14, 0.14};
  box.subdivisions = 2;
  box.cells = 7;
  cube.setup.name = "cube";
  cube.setup.velocity = {0, -0.5, -0.2};
  cube.asset = make_primitive_asset(box, 3);
  place_asset(cube.asset, {0, {0.0, 0.22, 0.05}, {0, 0, 0}});
  v.push_back(soft(std::move(cube)));
  WorldSettings s = with_box(deterministic(2));
  s.collision.update.mode = collision::SphereUpdateMode::DisplacementBound;  // as many_objects
  s.collision.contact.stiffness = 1000;
  for (const auto& [centre, half] : {std::pair<Eigen::Vector3d, Eigen::Vector3d>{{-0.45, 0, 0}, {0.05, 0.5, 0.5}},
                                     {{0.45, 0, 0}, {0.05, 0.5, 0.5}},
                                     {{0, -0.45, 0}, {0.5, 0.05, 0.5}},
                                     {{0, 0.45, 0}, {0.5, 0.05, 0.5}}}) {
    Obstacle wall;
    wall.type = Obstacle::Type::Box;
    wall.point = centre;
    wall.half_extents = half;
    s.obstacles.push_back(wall);
  }
  World world(std::move(v), s);
  double e0 = -1;
  int contact_frames = 0, obstacle_frames = 0;
  double deepest = 0;
  for (int f = 0; f < 60; ++f) {
    FrameMetrics m;
    ASSERT_NO_THROW(m = world.step()) << "frame " << f;
    if (e0 < 0) e0 = m.energy;
    EXPECT_LE(m.energy, e0 * 1.02) << "frame " << f;
    contact_frames += m.active_pairs > 0;
    obstacle_frames += m.obstacle_depth > 0;
    deepest = std::max(deepest, m.depth_ratio);
  }
  EXPECT_GE(contact_frames, 3);   // repeated contacts between the objects
  EXPECT_GE(obstacle_frames, 10);  // and with the box
  EXPECT_LT(deepest, 1.0);
}

TEST(WorldRealTime, RefusesBadThreadAndBudgetSettings) {
  WorldSettings s;
  s.threads = -1;
  EXPECT_THROW(validate(s), ParameterError);
  s = WorldSettings{};
  s.min_query_budget = 0;
  EXPECT_THROW(validate(s), ParameterError);
}

}  // namespace
}  // namespace icd::coupling
