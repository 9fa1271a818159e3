#pragma once
// The contact oracle of the collision tests: points where two dense surfaces
// truly intersect (exact triangle-triangle intersection), and the check that
// every one of them lies in both spheres of some pair a query reports, at
// every test budget and in every traversal mode.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include <icd/collision/aabb_tree.hpp>
#include <icd/collision/traversal.hpp>
#include <icd/collision/triangle_intersection.hpp>

namespace icd::collision::testing {

// Points of the true intersection of two dense surfaces: the hull vertices of
// every intersecting triangle pair and the midpoints between them.
inline std::vector<Eigen::Vector3d> contact_points(const MatX3d& Va, const MatX3i& Fa,
                                                   const MatX3d& Vb, const MatX3i& Fb) {
  const AabbTree ta(Va, Fa), tb(Vb, Fb);
  std::vector<Eigen::Vector3d> pts;
  for (const auto& [f, g] : intersecting_triangle_pairs(ta, Va, Fa, tb, Vb, Fb)) {
    const auto p =
        triangle_intersection_points(Va.row(Fa(f, 0)), Va.row(Fa(f, 1)), Va.row(Fa(f, 2)),
                                     Vb.row(Fb(g, 0)), Vb.row(Fb(g, 1)), Vb.row(Fb(g, 2)));
    for (std::size_t i = 0; i < p.size(); ++i) {
      pts.push_back(p[i]);
      for (std::size_t j = i + 1; j < p.size(); ++j) pts.push_back(0.5 * (p[i] + p[j]));
    }
  }
  return pts;
}

inline std::vector<int> nodes_containing(const SphereTree& t, const Eigen::Vector3d& p) {
  std::vector<int> out;
  for (int i = 0; i < t.num_nodes(); ++i) {
    const Sphere& s = t.spheres[i];
    if ((p - s.center()).norm() <= s.r + 1e-9) out.push_back(i);
  }
  return out;
}

// Checks the guarantee for many test budgets and every traversal mode.
inline void check_all_budgets(const SphereTree& a, const SphereTree& b,
                              const std::vector<Eigen::Vector3d>& pts) {
  ASSERT_GT(pts.size(), 20u);
  std::vector<std::vector<int>> in_a, in_b;
  for (const auto& p : pts) {
    in_a.push_back(nodes_containing(a, p));
    in_b.push_back(nodes_containing(b, p));
    ASSERT_FALSE(in_a.back().empty());
    ASSERT_FALSE(in_b.back().empty());
  }
  std::vector<CollisionRequest> requests;
  for (auto mode :
       {TraversalMode::BreadthFirstFifo, TraversalMode::DepthFirst, TraversalMode::Priority}) {
    CollisionRequest r;
    r.mode = mode;
    r.max_list_size = 64;
    requests.push_back(r);
  }
  requests.back().priority =
      PriorityKey::DeepestOverlap;  // the capped priority mode with both keys
  requests.push_back(requests.back());
  requests.back().priority = PriorityKey::LargestSphere;
  for (std::size_t k = 0, n = requests.size(); k < n; ++k) {  // the same with the parent filter
    requests.push_back(requests[k]);
    requests.back().parent_filter = true;
  }
  requests.push_back(CollisionRequest::paper_reference(std::numeric_limits<double>::infinity()));
  const int64_t full_tests = collide(a, b, CollisionRequest::paper_reference(INFINITY)).tests;
  int checked = 0, lossy_without_untested = 0;
  for (CollisionRequest r : requests) {
    for (int64_t budget = 0; budget <= full_tests + 1;
         budget = budget < 40 ? budget + 1 : budget * 5 / 4) {
      r.budget_tests = budget;
      const CollisionResult res = collide(a, b, r);
      std::unordered_set<uint64_t> leaf_pairs, reported;
      for (const NodePair& p : res.colliding)
        leaf_pairs.insert((uint64_t(uint32_t(p.a)) << 32) | uint32_t(p.b));
      reported = leaf_pairs;
      for (const NodePair& p : res.untested)
        reported.insert((uint64_t(uint32_t(p.a)) << 32) | uint32_t(p.b));
      auto covers = [&](const std::unordered_set<uint64_t>& set, std::size_t k) {
        for (int i : in_a[k])
          for (int j : in_b[k])
            if (set.count((uint64_t(uint32_t(i)) << 32) | uint32_t(j))) return true;
        return false;
      };
      bool leaves_alone_suffice = true;
      for (std::size_t k = 0; k < pts.size(); ++k) {
        ASSERT_TRUE(covers(reported, k))
            << "mode " << int(r.mode) << " filter " << r.parent_filter << " budget " << budget
            << ": contact point " << pts[k].transpose() << " under no reported pair";
        leaves_alone_suffice = leaves_alone_suffice && covers(leaf_pairs, k);
      }
      // The check has teeth: when interrupted early, dropping the untested
      // pairs (what a naive interrupted traversal would do) loses contacts.
      if (res.interrupted && !leaves_alone_suffice) ++lossy_without_untested;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(lossy_without_untested, 10);
}

}  // namespace icd::collision::testing
