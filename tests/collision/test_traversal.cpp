#include <gtest/gtest.h>

#include <icd/collision/traversal.hpp>
#include <icd/mesh/core/error.hpp>
#include "tree_fixtures.hpp"

namespace icd::collision {
namespace {

using namespace icd::collision::testing;

struct Scene {
  SphereTree a, b;
};

Scene torus_and_sphere(int levels, bool make_layered) {
  const SurfaceMesh ta = make_torus(1.0, 0.3, 32, 16);
  const SurfaceMesh sb = translated(make_icosphere(3, 0.6), {1.0, 0.2, 0.1});
  OctreeTreeOptions o;
  o.levels = levels;
  Scene s{build_octree_tree(ta.V, ta.F, o), build_octree_tree(sb.V, sb.F, o)};
  if (make_layered) {
    s.a = layered(s.a);
    s.b = layered(s.b);
  }
  return s;
}

std::vector<CollisionRequest> all_modes() {
  std::vector<CollisionRequest> v;
  for (auto mode : {TraversalMode::BreadthFirstFifo, TraversalMode::BreadthFirstLiteral,
                    TraversalMode::DepthFirst, TraversalMode::DepthFirstLiteral,
                    TraversalMode::Priority}) {
    CollisionRequest r;
    r.mode = mode;
    r.max_list_size = 1 << 20;
    v.push_back(r);
  }
  CollisionRequest deepest;
  deepest.mode = TraversalMode::Priority;
  deepest.priority = PriorityKey::DeepestOverlap;
  deepest.max_list_size = 1 << 20;
  v.push_back(deepest);
  v.push_back(CollisionRequest::paper_reference(std::numeric_limits<double>::infinity()));
  return v;
}

// The fast modes with CollisionRequest::parent_filter.
std::vector<CollisionRequest> filtered_modes() {
  std::vector<CollisionRequest> v;
  for (const CollisionRequest& r : all_modes())
    if (!is_literal(r.mode)) {
      v.push_back(r);
      v.back().parent_filter = true;
    }
  return v;
}

std::string describe(const CollisionRequest& r) {
  return "mode " + std::to_string(int(r.mode)) +
         " filter " + std::to_string(r.parent_filter) + " priority " +
         std::to_string(int(r.priority));
}

TEST(Traversal, FullTraversalOfLayeredTreesEqualsBruteForceLeafPairs) {
  const Scene s = torus_and_sphere(4, true);
  const auto expected = brute_force_leaf_overlaps(s.a, s.b);
  ASSERT_GT(expected.size(), 10u);
  // The parent filter prunes nothing here: in a layered tree a child lies in
  // its parent, so a child overlapping the other side overlaps its parent too.
  auto modes = all_modes();
  for (const CollisionRequest& r : filtered_modes()) modes.push_back(r);
  for (const CollisionRequest& r : modes) {
    const CollisionResult res = collide(s.a, s.b, r);
    EXPECT_FALSE(res.interrupted);
    EXPECT_EQ(res.stop_reason, StopReason::Completed);
    EXPECT_TRUE(res.untested.empty());
    EXPECT_EQ(as_set(res.colliding), expected) << describe(r);
    EXPECT_EQ(res.colliding.size(), expected.size());  // no duplicates
    EXPECT_EQ(res.completed_level, 3);
  }
}

// Every ancestor-or-self of leaf i overlaps every ancestor-or-self of leaf j:
// then any traversal that prunes on overlaps of ancestors keeps (i, j).
bool all_ancestor_pairs_overlap(const SphereTree& a, const SphereTree& b,
                                const std::vector<int32_t>& pa, const std::vector<int32_t>& pb,
                                int i, int j) {
  for (int x = i; x >= 0; x = pa[x])
    for (int y = j; y >= 0; y = pb[y])
      if (!overlap(a.spheres[x], b.spheres[y])) return false;
  return true;
}

TEST(Traversal, WrappedTreesAllModesAgreeAndSitBetweenOracles) {
  const Scene s = torus_and_sphere(4, false);
  const auto upper = brute_force_leaf_overlaps(s.a, s.b);
  const auto pa = parents(s.a), pb = parents(s.b);
  const CollisionResult ref =
      collide(s.a, s.b, CollisionRequest::paper_reference(std::numeric_limits<double>::infinity()));
  const auto ref_set = as_set(ref.colliding);
  for (const CollisionRequest& r : all_modes())
    EXPECT_EQ(as_set(collide(s.a, s.b, r).colliding), ref_set);
  // Reported leaf pairs overlap; leaf pairs whose every ancestor combination overlaps are reported.
  for (const auto& p : ref_set) EXPECT_TRUE(upper.count(p));
  for (const auto& [i, j] : upper)
    if (all_ancestor_pairs_overlap(s.a, s.b, pa, pb, i, j)) {
      EXPECT_TRUE(ref_set.count({i, j}));
    }
}

// The parent filter's rule for one leaf pair, walked along its path in the
// pair tree (Fig. 7: b split first, then the sides alternate, a leaf's side
// skipped): every pair on the path overlaps, and when a split of one side
// queues two or more pairs (overlapping children of it that it may take,
// with the other node or one of them still to split), the child taken at the
// next split of the other side must also overlap the node just split.
bool filter_rule_reports(const SphereTree& a, const SphereTree& b, const std::vector<int32_t>& pa,
                         const std::vector<int32_t>& pb, int i, int j) {
  auto chain = [](const std::vector<int32_t>& parent, int leaf) {
    std::vector<int> c;
    for (int n = leaf; n >= 0; n = parent[n]) c.insert(c.begin(), n);
    return c;
  };
  const std::vector<int> ca = chain(pa, i), cb = chain(pb, j);
  std::size_t ka = 0, kb = 0;
  bool flag_b = true;
  std::vector<char> allowed;  // empty: every child of the node split next
  while (true) {
    if (!overlap(a.spheres[ca[ka]], b.spheres[cb[kb]])) return false;
    const bool ea = ka + 1 < ca.size(), eb = kb + 1 < cb.size();
    if (!ea && !eb) return true;
    const bool split_b = flag_b ? eb : (!ea && eb);
    const SphereTree& ts = split_b ? b : a;  // the split side
    const SphereTree& to = split_b ? a : b;
    const int x = split_b ? cb[kb] : ca[ka], y = split_b ? ca[ka] : cb[kb];
    const int taken = split_b ? cb[kb + 1] : ca[ka + 1];
    if (!allowed.empty() && !allowed[taken - ts.first_child[x]]) return false;
    const bool y_splits = !to.is_leaf(y);
    int queued = 0;
    for (int k = 0; k < ts.child_count[x]; ++k) {
      const int c = ts.first_child[x] + k;
      const bool may = allowed.empty() || allowed[k];
      queued += may && overlap(ts.spheres[c], to.spheres[y]) && (y_splits || !ts.is_leaf(c));
    }
    allowed.clear();
    if (y_splits && queued >= 2)
      for (int k = 0; k < to.child_count[y]; ++k)
        allowed.push_back(overlap(to.spheres[to.first_child[y] + k], ts.spheres[x]));
    (split_b ? kb : ka) += 1;
    flag_b = !split_b;
  }
}

TEST(Traversal, ParentFilterReportsExactlyItsRuleAndPrunesOnWrappedTrees) {
  // The octree's cell spheres nest, so the filter would prune nothing there:
  // inner spheres shrunk make children stick out of their parents, as in a
  // wrapped tree (the rule needs no covering).
  for (int levels : {4, 5}) {
    Scene s = torus_and_sphere(levels, false);
    for (SphereTree* t : {&s.a, &s.b})
      for (int i = 0; i < t->num_nodes(); ++i)
        if (!t->is_leaf(i)) t->spheres[i].r *= 0.8;
    const auto pa = parents(s.a), pb = parents(s.b);
    std::set<std::pair<int, int>> expected;
    for (const auto& [i, j] : brute_force_leaf_overlaps(s.a, s.b))
      if (filter_rule_reports(s.a, s.b, pa, pb, i, j)) expected.insert({i, j});
    const CollisionResult plain = collide(s.a, s.b, CollisionRequest{});
    const auto plain_set = as_set(plain.colliding);
    // The rule has teeth here: it drops leaf pairs the plain traversal reports.
    ASSERT_LT(expected.size(), plain_set.size());
    ASSERT_GT(expected.size(), 10u);
    for (const auto& p : expected) EXPECT_TRUE(plain_set.count(p));
    for (const CollisionRequest& r : filtered_modes()) {
      const CollisionResult res = collide(s.a, s.b, r);
      EXPECT_FALSE(res.interrupted);
      EXPECT_TRUE(res.untested.empty());
      EXPECT_EQ(as_set(res.colliding), expected) << describe(r);
      EXPECT_EQ(res.colliding.size(), expected.size()) << describe(r);  // no duplicates
      EXPECT_LT(res.tests, plain.tests) << describe(r);                 // filter tests included
    }
  }
}

// Every leaf pair found by the full traversal lies under some reported pair.
void expect_cut_covers(const SphereTree& a, const SphereTree& b,
                       const std::set<std::pair<int, int>>& full, const CollisionResult& res) {
  const auto pa = parents(a), pb = parents(b);
  std::vector<NodePair> reported = res.colliding;
  reported.insert(reported.end(), res.untested.begin(), res.untested.end());
  for (const auto& [i, j] : full) {
    bool under = false;
    for (const NodePair& p : reported)
      if (is_ancestor_or_self(pa, p.a, i) && is_ancestor_or_self(pb, p.b, j)) {
        under = true;
        break;
      }
    ASSERT_TRUE(under) << "leaf pair (" << i << ", " << j << ") lost";
  }
}

TEST(Traversal, InterruptedAtAnyTestBudgetIsConservativeOnThePairTree) {
  const Scene s = torus_and_sphere(4, false);
  auto modes = all_modes();
  for (const CollisionRequest& r : filtered_modes()) modes.push_back(r);
  for (CollisionRequest r : modes) {
    // The full traversal of the same request (the filter's set is smaller).
    const CollisionResult full = collide(s.a, s.b, r);
    const auto full_set = as_set(full.colliding);
    for (int64_t budget = 0; budget <= full.tests + 10; budget += 1 + budget / 3) {
      r.budget_tests = budget;
      const CollisionResult res = collide(s.a, s.b, r);
      EXPECT_LE(res.tests, budget);
      if (res.interrupted) {
        EXPECT_EQ(res.tests, budget);
        EXPECT_EQ(res.stop_reason, StopReason::TestBudget);
      }
      expect_cut_covers(s.a, s.b, full_set, res);
    }
  }
}

TEST(Traversal, InterruptedByTheClockIsConservativeOnThePairTree) {
  // Wherever the clock stops the query, the answer must cover every leaf pair
  // of the full traversal (the stop point varies from run to run; the
  // property may not).
  const Scene s = torus_and_sphere(4, false);
  int interrupted = 0;
  auto modes = all_modes();
  for (const CollisionRequest& r : filtered_modes()) modes.push_back(r);
  for (CollisionRequest r : modes) {
    const auto full_set = as_set(collide(s.a, s.b, r).colliding);
    for (ClockSource clock : {ClockSource::SteadyClock, ClockSource::CycleCounter}) {
      for (double budget : {1e-7, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4}) {
        r.budget_seconds = budget;
        r.clock = clock;
        r.clock_check_interval = 1 + static_cast<int>(budget * 1e6) % 7;
        const CollisionResult res = collide(s.a, s.b, r);
        if (res.interrupted) {
          ++interrupted;
          EXPECT_EQ(res.stop_reason, StopReason::TimeBudget);
        }
        expect_cut_covers(s.a, s.b, full_set, res);
      }
    }
  }
  EXPECT_GT(interrupted, 0);
}

TEST(Traversal, BreadthFirstRefinesLevelByLevel) {
  const Scene s = torus_and_sphere(4, false);
  CollisionRequest r = CollisionRequest::paper_reference(std::numeric_limits<double>::infinity());
  int last = 0;
  for (int64_t budget = 1; budget < 4000; budget *= 2) {
    r.budget_tests = budget;
    const CollisionResult res = collide(s.a, s.b, r);
    EXPECT_GE(res.completed_level, last);
    last = res.completed_level;
    // FIFO: no untested pair is more than one level apart from another.
    int lo = 100, hi = -1;
    for (const NodePair& p : res.untested) {
      lo = std::min(lo, std::min<int>(s.a.level[p.a], s.b.level[p.b]));
      hi = std::max(hi, std::min<int>(s.a.level[p.a], s.b.level[p.b]));
    }
    if (!res.untested.empty()) {
      EXPECT_LE(hi - lo, 1);
    }
  }
  EXPECT_EQ(last, 3);
}

TEST(Traversal, PriorityWithSmallCapStaysConservative) {
  const Scene s = torus_and_sphere(4, false);
  const auto full_set = as_set(collide(s.a, s.b, CollisionRequest{}).colliding);
  CollisionRequest r;
  r.mode = TraversalMode::Priority;
  r.max_list_size = 16;
  const CollisionResult res = collide(s.a, s.b, r);
  EXPECT_LE(res.peak_list_size, 16u);
  EXPECT_FALSE(res.interrupted);
  EXPECT_FALSE(res.untested.empty());  // the cap held some pairs back
  expect_cut_covers(s.a, s.b, full_set, res);
}

TEST(Traversal, DepthCapStopsAtTheLevel) {
  const Scene s = torus_and_sphere(4, false);
  const auto full_set = as_set(collide(s.a, s.b, CollisionRequest{}).colliding);
  CollisionRequest r;
  r.mode = TraversalMode::DepthFirst;
  r.depth_cap = 2;
  const CollisionResult res = collide(s.a, s.b, r);
  EXPECT_TRUE(res.colliding.empty());
  for (const NodePair& p : res.untested) {
    EXPECT_LE(s.a.level[p.a], 2);
    EXPECT_LE(s.b.level[p.b], 2);
  }
  EXPECT_EQ(res.completed_level, 2);
  expect_cut_covers(s.a, s.b, full_set, res);
}

TEST(Traversal, TemporalCoherenceFrontIsConservative) {
  for (bool make_layered : {true, false})
    for (bool filter : {false, true}) {
      Scene s = torus_and_sphere(4, make_layered);
      CollisionRequest r;
      r.record_front = true;
      r.parent_filter = filter;
      CollisionRequest from_roots_request;
      from_roots_request.parent_filter = filter;
      CollisionResult prev = collide(s.a, s.b, r);
      // Move b a little each frame; starting from the previous front must find
      // what a query from the roots finds (exactly so for layered trees; for
      // wrapped trees it may keep pairs whose ancestors separated).
      for (int frame = 1; frame <= 5; ++frame) {
        for (Sphere& sp : s.b.spheres) {
          sp.x += 0.03;
          sp.y -= 0.01;
        }
        const auto from_roots = as_set(collide(s.a, s.b, from_roots_request).colliding);
        CollisionRequest rf = r;
        rf.start_front = &prev.front;
        const CollisionResult from_front = collide(s.a, s.b, rf);
        const auto got = as_set(from_front.colliding);
        if (make_layered) {
          EXPECT_EQ(got, from_roots) << "frame " << frame;
        } else if (filter) {
          // From the front the filter has no parents above it, and which splits
          // make a mask depends on the pairs beside: the sets need not nest, but
          // every leaf pair all of whose ancestor pairs overlap is kept.
          const auto pa = parents(s.a), pb = parents(s.b);
          const auto upper = brute_force_leaf_overlaps(s.a, s.b);
          for (const auto& [i, j] : upper)
            if (all_ancestor_pairs_overlap(s.a, s.b, pa, pb, i, j)) {
              EXPECT_TRUE(got.count({i, j})) << "frame " << frame;
            }
          for (const auto& p : got) EXPECT_TRUE(upper.count(p)) << "frame " << frame;
        } else {
          for (const auto& p : from_roots) EXPECT_TRUE(got.count(p)) << "frame " << frame;
          const auto upper = brute_force_leaf_overlaps(s.a, s.b);
          for (const auto& p : got) EXPECT_TRUE(upper.count(p)) << "frame " << frame;
        }
        prev = from_front;
      }
    }
}

TEST(Traversal, TemporalCoherenceRefinesInterruptedQueriesOverFrames) {
  const Scene s = torus_and_sphere(4, true);
  const CollisionResult full = collide(s.a, s.b, CollisionRequest{});
  const auto full_set = as_set(full.colliding);
  CollisionRequest ri;
  ri.record_front = true;
  ri.budget_tests = (3 * full.tests) / 4;
  const CollisionResult from_roots = collide(s.a, s.b, ri);
  ASSERT_TRUE(from_roots.interrupted);
  CollisionResult cur = from_roots;
  for (int frame = 0; frame < 6; ++frame) {
    const std::vector<NodePair> front = cur.front;
    ri.start_front = &front;
    const CollisionResult next = collide(s.a, s.b, ri);
    expect_cut_covers(s.a, s.b, full_set, next);
    // Same budget, a tighter answer than the previous frame's.
    EXPECT_LE(next.untested.size(), cur.untested.size());
    EXPECT_GE(next.colliding.size(), cur.colliding.size());
    cur = next;
  }
  EXPECT_LT(cur.untested.size(), from_roots.untested.size() / 4);
  EXPECT_GT(cur.colliding.size(), from_roots.colliding.size());
  for (const NodePair& p : cur.colliding) EXPECT_TRUE(full_set.count({p.a, p.b}));
}

TEST(Traversal, TimeBudgetStopsAndRejectsBadRequests) {
  const Scene s = torus_and_sphere(4, false);
  CollisionRequest r;
  r.budget_seconds = 1e-9;
  const CollisionResult res = collide(s.a, s.b, r);
  EXPECT_TRUE(res.interrupted);
  EXPECT_EQ(res.stop_reason, StopReason::TimeBudget);
  EXPECT_EQ(res.completed_level, 0);
  r.clock = ClockSource::CycleCounter;
  EXPECT_TRUE(collide(s.a, s.b, r).interrupted);
  CollisionRequest bad;
  bad.budget_seconds = 0;
  EXPECT_THROW(collide(s.a, s.b, bad), ParameterError);
  bad = {};
  bad.clock_check_interval = 0;
  EXPECT_THROW(collide(s.a, s.b, bad), ParameterError);
  bad = {};
  bad.budget_tests = -5;
  EXPECT_THROW(collide(s.a, s.b, bad), ParameterError);
  std::vector<NodePair> front{{0, 100000}};
  bad = {};
  bad.start_front = &front;
  EXPECT_THROW(collide(s.a, s.b, bad), ParameterError);
}

}  // namespace
}  // namespace icd::collision
