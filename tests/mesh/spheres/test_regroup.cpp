// regroup_children (mesh/spheres/regroup.hpp) on random instances built from
// points (children as balls, parents as centres): the capacity holds, no
// parent that had children is emptied, a feasible start never gets worse,
// and the result is a local optimum checked by brute force over every single
// move and every swap (not only the ones the function tries).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/regroup.hpp>

namespace {

using icd::mesh::regroup_children;
using icd::mesh::regroup_cost;
using Reach = std::vector<std::vector<double>>;

struct Instance {
  Reach reach;
  std::vector<int> parent;  // nearest parent: overfull where children crowd
};

/// Children are balls (centre, radius) and parents points in the unit cube;
/// the reach of a parent is the distance to a child's centre plus its radius,
/// which is what covering the child's samples costs a sphere at the parent.
Instance random_instance(std::mt19937& rng, int children, int parents) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::array<double, 3>> c(static_cast<size_t>(children)),
      p(static_cast<size_t>(parents));
  std::vector<double> r(static_cast<size_t>(children));
  // Children crowd around the first parent so that its nearest-parent group overflows.
  for (auto& x : p) x = {u(rng), u(rng), u(rng)};
  for (size_t i = 0; i < c.size(); ++i) {
    const auto& spot = p[0];
    for (int k = 0; k < 3; ++k)
      c[i][static_cast<size_t>(k)] = spot[static_cast<size_t>(k)] + 0.3 * (u(rng) - 0.5);
    r[i] = 0.05 * u(rng);
  }
  Instance in;
  in.reach.assign(c.size(), std::vector<double>(p.size()));
  for (size_t i = 0; i < c.size(); ++i) {
    int nearest = 0;
    for (size_t q = 0; q < p.size(); ++q) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double d = c[i][static_cast<size_t>(k)] - p[q][static_cast<size_t>(k)];
        d2 += d * d;
      }
      in.reach[i][q] = std::sqrt(d2) + r[i];
      if (in.reach[i][q] < in.reach[i][static_cast<size_t>(nearest)]) nearest = static_cast<int>(q);
    }
    in.parent.push_back(nearest);
  }
  return in;
}

std::vector<int> counts(const std::vector<int>& parent, int m) {
  std::vector<int> n(static_cast<size_t>(m), 0);
  for (int p : parent) n[static_cast<size_t>(p)] += 1;
  return n;
}

/// True when no single move (to a parent with room, leaving the giver
/// non-empty) and no swap lowers the cost by more than `tol`.
bool locally_optimal(const Reach& reach, std::vector<int> parent, int m, int capacity, double tol) {
  const double cost = regroup_cost(reach, parent, m);
  const std::vector<int> n = counts(parent, m);
  for (size_t i = 0; i < parent.size(); ++i) {
    const int p = parent[i];
    for (int q = 0; q < m; ++q) {
      if (q == p || n[static_cast<size_t>(q)] >= capacity || n[static_cast<size_t>(p)] <= 1)
        continue;
      parent[i] = q;
      const bool better = regroup_cost(reach, parent, m) < cost - tol;
      parent[i] = p;
      if (better) return false;
    }
    for (size_t j = 0; j < parent.size(); ++j) {
      if (parent[j] == p) continue;
      std::swap(parent[i], parent[j]);
      const bool better = regroup_cost(reach, parent, m) < cost - tol;
      std::swap(parent[i], parent[j]);
      if (better) return false;
    }
  }
  return true;
}

TEST(RegroupChildren, RespectsCapacityAndEndsInALocalOptimum) {
  std::mt19937 rng(7);
  int repaired = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int m = 2 + trial % 7, capacity = 1 + trial % 4;
    const int n = std::max(m, m * capacity - trial % 3);
    const Instance in = random_instance(rng, n, m);
    const std::vector<int> start = counts(in.parent, m);
    if (std::none_of(start.begin(), start.end(), [&](int c) { return c > capacity; })) continue;
    ++repaired;
    const std::vector<int> out = regroup_children(in.reach, in.parent, capacity);
    ASSERT_EQ(out.size(), in.parent.size());
    const std::vector<int> end = counts(out, m);
    for (int q = 0; q < m; ++q) {
      EXPECT_LE(end[static_cast<size_t>(q)], capacity) << "trial " << trial << ", parent " << q;
      if (start[static_cast<size_t>(q)] > 0) {
        EXPECT_GE(end[static_cast<size_t>(q)], 1)
            << "trial " << trial << ": parent " << q << " emptied";
      }
    }
    EXPECT_TRUE(locally_optimal(in.reach, out, m, capacity, 1e-9)) << "trial " << trial;
  }
  EXPECT_GE(repaired, 40);  // most instances start overfull
}

TEST(RegroupChildren, AFeasibleStartOnlyImproves) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    const int m = 3 + trial % 5, capacity = 3;
    const int n = m * capacity - 1;
    Instance in = random_instance(rng, n, m);
    // A feasible but poor start: children dealt round-robin.
    for (size_t i = 0; i < in.parent.size(); ++i) in.parent[i] = static_cast<int>(i) % m;
    const double before = regroup_cost(in.reach, in.parent, m);
    const std::vector<int> out = regroup_children(in.reach, in.parent, capacity);
    EXPECT_LE(regroup_cost(in.reach, out, m), before + 1e-12) << "trial " << trial;
    EXPECT_TRUE(locally_optimal(in.reach, out, m, capacity, 1e-9)) << "trial " << trial;
    for (int c : counts(out, m)) EXPECT_LE(c, capacity);
  }
}

TEST(RegroupChildren, KeepsAnOptimalAssignment) {
  // Two clusters far apart, each under its own parent: nothing to change.
  const Reach reach = {{1, 10}, {1, 10}, {10, 1}, {10, 2}};
  const std::vector<int> parent = {0, 0, 1, 1};
  EXPECT_EQ(regroup_children(reach, parent, 2), parent);
  // One child too many under parent 0: the one cheapest for parent 1 moves.
  const Reach crowded = {{1, 9}, {1, 5}, {1, 10}, {10, 1}};
  EXPECT_EQ(regroup_children(crowded, {0, 0, 0, 1}, 2), (std::vector<int>{0, 1, 0, 1}));
}

TEST(RegroupChildren, RejectsImpossibleInput) {
  const Reach reach = {{1, 2}, {1, 2}, {1, 2}};
  EXPECT_THROW(regroup_children(reach, {0, 0, 1}, 1), icd::ParameterError);  // 3 > 2 x 1
  EXPECT_THROW(regroup_children(reach, {0, 0, 1}, 0), icd::ParameterError);
  EXPECT_THROW(regroup_children(reach, {0, 0, 2}, 2), icd::ParameterError);
  EXPECT_THROW(regroup_children({{1, 2}, {1}}, {0, 1}, 2), icd::ParameterError);
  EXPECT_THROW(regroup_children({{1, -2}, {1, 2}}, {0, 1}, 2), icd::ParameterError);
  EXPECT_THROW(regroup_children(reach, {0, 0}, 2), icd::ParameterError);  // sizes differ
}

}  // namespace
