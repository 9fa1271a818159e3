#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>

#include <icd/collision/traversal.hpp>
#include "experiments/runner/run.hpp"

namespace icd::runner {
namespace {

constexpr int kAll = std::numeric_limits<int>::max();

Scene two_spheres(const std::string& collision) {
  const std::string text = R"({
    "objects": [
      {"name": "a", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 3}, "position": [-0.05, 0, 0]},
      {"name": "b", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 3}, "position": [0.05, 0.01, 0]}
    ],
    "collision": {)" + collision +
                           R"(}, "output": {"csv": false}})";
  return parse_scene(parse_json(text, "levels"), "levels", ".");
}

int deepest_level(const collision::SphereTree& ta, const collision::SphereTree& tb,
                  const collision::CollisionResult& r) {
  int d = 0;
  for (const auto* list : {&r.colliding, &r.untested})
    for (const collision::NodePair& p : *list) d = std::max({d, ta.level[p.a], tb.level[p.b]});
  return d;
}

TEST(PlanLevels, BoundFollowsDepthCapAndTestBudget) {
  using coupling::max_usable_level;
  EXPECT_EQ(max_usable_level(-1), kAll);
  EXPECT_EQ(max_usable_level(0), 0);
  EXPECT_EQ(max_usable_level(5), 3);
  EXPECT_EQ(max_usable_level(1000000), kAll);
  EXPECT_EQ(max_usable_level(1), 1);

  Scene s = two_spheres(R"("budget_seconds": 0.001, "depth_cap": 1)");
  coupling::StagePlan p = scene_plan(s);
  EXPECT_EQ(p.max_tree_level, 1);
  EXPECT_EQ(p.tree_cut, coupling::TreeCut::DepthCap);
  auto lines = describe_plan(s);
  EXPECT_NE(std::find(lines.begin(), lines.end(),
                      "sphere trees: levels 0..1 only (collision.depth_cap; deeper levels not "
                      "loaded, not updated)"),
            lines.end());
  s = two_spheres(R"("budget_tests": 2)");
  p = scene_plan(s);
  EXPECT_EQ(p.max_tree_level, 1);
  EXPECT_EQ(p.tree_cut, coupling::TreeCut::TestBudget);
  lines = describe_plan(s);
  EXPECT_NE(std::find(lines.begin(), lines.end(),
                      "sphere trees: levels 0..1 only (a level-L sphere needs 2L - 1 tests first, "
                      "beyond the budget of 2 tests; deeper levels not loaded, not updated)"),
            lines.end());
}

// A time budget cuts no level, and the plan does not claim that the queries
// reach the leaves: how deep they get depends on the machine.
TEST(PlanLevels, TimeBudgetsCutNoLevelAndClaimNothing) {
  for (const char* budget : {R"("budget_seconds": 0.001)", R"("budget_seconds": 1e-6)",
                             R"("budget_seconds": 1e-9)"}) {
    const Scene s = two_spheres(budget);
    const coupling::StagePlan p = scene_plan(s);
    EXPECT_EQ(p.max_tree_level, kAll) << budget;
    EXPECT_EQ(p.tree_cut, coupling::TreeCut::None) << budget;
    const auto lines = describe_plan(s);
    ASSERT_GE(lines.size(), 4u);
    EXPECT_EQ(lines[2],
              "sphere trees: every level kept (a time budget cuts no level: how deep a query gets "
              "depends on the machine and the pair)")
        << budget;
    for (const std::string& l : lines) EXPECT_EQ(l.find("reach the leaves"), std::string::npos);
  }
  EXPECT_EQ(describe_plan(two_spheres(R"("budget_tests": 20000)"))[2],
            "sphere trees: every level kept (a budget of 20000 tests cuts no level)");
  EXPECT_EQ(describe_plan(two_spheres(R"("unlimited": true)"))[2],
            "sphere trees: every level kept (no budget, no depth cap)");
}

// Oracle: for every test budget and traversal mode, the query on the full
// trees never reports a pair deeper than the bound, and the trees cut at the
// bound give exactly the same answer -- cutting loses nothing.
TEST(PlanLevels, CutTreesGiveTheSameAnswerAsFullTrees) {
  World world = make_world(two_spheres(R"("unlimited": true)"), "", "");
  const collision::SphereTree& fa = world.objects()[0].asset.spheres;
  const collision::SphereTree& fb = world.objects()[1].asset.spheres;
  ASSERT_GE(fa.num_levels(), 3);
  int cut_cases = 0;
  for (collision::TraversalMode mode :
       {collision::TraversalMode::BreadthFirstFifo, collision::TraversalMode::DepthFirst,
        collision::TraversalMode::Priority})
    for (int64_t n = 0; n <= 24; ++n) {
      collision::CollisionRequest req;
      req.mode = mode;
      req.budget_tests = n;
      const collision::CollisionResult full = collision::collide(fa, fb, req);
      const int bound = coupling::max_usable_level(n);
      ASSERT_LE(deepest_level(fa, fb, full), bound) << "budget " << n;
      if (bound + 1 >= fa.num_levels()) continue;
      collision::SphereTree ca = fa, cb = fb;
      collision::truncate_levels(ca, bound);
      collision::truncate_levels(cb, bound);
      ASSERT_EQ(ca.num_levels(), bound + 1);
      const collision::CollisionResult cut = collision::collide(ca, cb, req);
      EXPECT_EQ(cut.colliding, full.colliding) << "budget " << n;
      EXPECT_EQ(cut.untested, full.untested) << "budget " << n;
      EXPECT_EQ(cut.tests, full.tests);
      ++cut_cases;
    }
  EXPECT_GT(cut_cases, 10);
}

TEST(PlanLevels, WorldLoadsOnlyTheUsableLevels) {
  World capped = make_world(two_spheres(R"("budget_seconds": 0.001, "depth_cap": 1)"), "", "");
  World full = make_world(two_spheres(R"("budget_seconds": 0.001)"), "", "");
  const collision::SphereTree& c = capped.objects()[0].asset.spheres;
  const collision::SphereTree& f = full.objects()[0].asset.spheres;
  EXPECT_EQ(c.num_levels(), 2);
  EXPECT_GT(f.num_levels(), 2);
  EXPECT_EQ(c.num_nodes(), f.level_offset[2]);
  EXPECT_EQ(c.assoc_offset.size(), static_cast<size_t>(c.num_nodes()) + 1);
  collision::validate(c);
}

}  // namespace
}  // namespace icd::runner
