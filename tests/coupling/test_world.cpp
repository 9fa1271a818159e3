// The simulation loop as a library: a World built from objects in memory,
// with no scene file, no asset cache and no subprocess.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/world.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

WorldObject ball(const std::string& name, double x, double vx) {
  PrimitiveSpec p;
  p.radius = 0.1;
  p.subdivisions = 2;
  p.cells = 5;
  WorldObject o;
  o.setup.name = name;
  o.setup.material.young = 5e5;
  o.setup.velocity = {vx, 0, 0};
  o.asset = make_primitive_asset(p, 3);
  place_asset(o.asset, {0, {x, 0, 0}, {0, 0, 0}});
  return o;
}

WorldSettings head_on_settings() {
  WorldSettings s;
  s.collision.query.budget_tests = 1000000;
  s.collision.query.budget_seconds = std::numeric_limits<double>::infinity();
  s.collision.contact.stiffness = 2000;
  return s;
}

Eigen::Vector3d momentum(const RuntimeObject& o) {
  return o.sim->velocities().transpose() * o.sim->model().mass();
}

// Two soft balls meet head-on: the World finds the contact and they bounce
// apart with equal and opposite momenta (contact forces are equal and
// opposite), without creating energy.
TEST(World, RunsFromObjectsInMemoryAndBounces) {
  std::vector<WorldObject> objects;
  objects.push_back(ball("left", -0.12, 0.6));
  objects.push_back(ball("right", 0.12, -0.6));
  World world(std::move(objects), head_on_settings());
  ASSERT_EQ(world.plan().pairs.size(), 1u);
  EXPECT_TRUE(world.plan().response);
  const auto& o = world.objects();
  const double mass = o[0].sim->model().mass().sum();
  int contact_frames = 0;
  double first_energy = 0, last_energy = 0;
  for (int f = 0; f < 40; ++f) {
    const FrameMetrics m = world.step();
    if (f == 0) first_energy = m.energy;
    last_energy = m.energy;
    contact_frames += m.active_pairs > 0;
    ASSERT_LT((momentum(o[0]) + momentum(o[1])).norm(), 1e-9 * mass) << "frame " << f;
  }
  EXPECT_GT(contact_frames, 0);
  EXPECT_LT(momentum(o[0]).x() / mass, -0.1);  // moving apart
  EXPECT_GT(momentum(o[1]).x() / mass, 0.1);
  EXPECT_LE(last_energy, 1.05 * first_energy);
}

// A ball squeezed between two others (three in a row, the outer ones
// moving in): its nodes take part in two pairs. The per-node rate cap
// weighs each node against its rate over both pairs, so the springs stay
// under the stable rate together and no cycle is softened. (Summing each
// pair's bound instead, 2 x 0.9 / h^2 > 1 / h^2, softened every cycle of
// the contact, and the scale only falls during a contact: the penalty
// went soft for good.) The energy stays bounded and the balls do not pass
// through each other.
TEST(World, BallBetweenTwoOthersIsNotSoftened) {
  std::vector<WorldObject> objects;
  objects.push_back(ball("left", -0.205, 0.4));
  objects.push_back(ball("middle", 0, 0));
  objects.push_back(ball("right", 0.205, -0.4));
  WorldSettings s = head_on_settings();
  s.collision.contact.stiffness = 1e6;  // far above what 64 cycles hold: the cap acts
  World world(std::move(objects), s);
  ASSERT_EQ(world.plan().pairs.size(), 3u);
  const auto& o = world.objects();
  int softened = 0, both = 0;
  int64_t capped = 0;
  double e0 = 0, e_max = 0;
  for (int f = 0; f < 20; ++f) {
    const FrameMetrics m = world.step();
    if (f == 0) e0 = m.energy;
    e_max = std::max(e_max, m.energy);
    softened += m.softened;
    capped += m.capped_pairs;
    both += world.results()[0].colliding.size() > 0 && world.results()[2].colliding.size() > 0;
    ASSERT_LT(o[0].positions.col(0).mean(), o[1].positions.col(0).mean()) << "frame " << f;
    ASSERT_LT(o[1].positions.col(0).mean(), o[2].positions.col(0).mean()) << "frame " << f;
  }
  EXPECT_GT(both, 0);    // the middle ball was in both pairs at once
  EXPECT_GT(capped, 0);  // and the cap acted
  EXPECT_EQ(softened, 0);
  EXPECT_LT(e_max, 1.02 * e0);
}

TEST(World, RefusesInvalidSettingsAndObjectsByName) {
  {
    WorldSettings s = head_on_settings();
    s.collision.query.budget_seconds = 0;
    std::vector<WorldObject> objects{ball("a", -0.12, 0.6), ball("b", 0.12, -0.6)};
    EXPECT_THROW(World(std::move(objects), s), ParameterError);
  }
  {
    WorldSettings s = head_on_settings();
    s.frame_rate = 0;
    std::vector<WorldObject> objects{ball("a", -0.12, 0.6)};
    EXPECT_THROW(World(std::move(objects), s), ParameterError);
  }
  std::vector<WorldObject> objects{ball("a", -0.12, 0.6), ball("lonely", 0.12, -0.6)};
  objects[1].setup.fixed_nodes = {100000};
  try {
    World w(std::move(objects), head_on_settings());
    FAIL() << "a fixed node out of range was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"lonely\""), std::string::npos) << e.what();
  }
  std::vector<WorldObject> two{ball("a", -0.12, 0.6), ball("b", 0.12, -0.6)};
  World w(std::move(two), head_on_settings());
  EXPECT_THROW(w.step(0.0), ParameterError);
}

// The plan says why trees are cut, and the World applies exactly that cut.
TEST(World, CutsTreesWhereThePlanSays) {
  WorldSettings s = head_on_settings();
  s.collision.query.budget_tests = 3;  // 2L - 1 <= 3: levels 0..2
  std::vector<WorldObject> objects{ball("a", -0.12, 0.6), ball("b", 0.12, -0.6)};
  const int full_levels = objects[0].asset.spheres.num_levels();
  ASSERT_GT(full_levels, 3);
  World w(std::move(objects), s);
  EXPECT_EQ(w.plan().tree_cut, TreeCut::TestBudget);
  EXPECT_EQ(w.plan().max_tree_level, 2);
  EXPECT_EQ(w.objects()[0].asset.spheres.num_levels(), 3);

  s.collision.query.budget_tests = -1;
  s.collision.query.depth_cap = 1;
  std::vector<WorldObject> capped{ball("a", -0.12, 0.6), ball("b", 0.12, -0.6)};
  World c(std::move(capped), s);
  EXPECT_EQ(c.plan().tree_cut, TreeCut::DepthCap);
  EXPECT_EQ(c.objects()[1].asset.spheres.num_levels(), 2);
}

}  // namespace
}  // namespace icd::coupling
