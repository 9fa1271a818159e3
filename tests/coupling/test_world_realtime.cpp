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
