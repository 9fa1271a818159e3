// allocate_children (mesh/spheres/allocation.hpp) against brute force over
// every allocation of small random instances: the cap is spent, a feasible
// worst threshold is met, and on instances where greedy is provably optimal
// (worst bounds falling with k, summed bounds convex) the threshold rule
// reaches the exhaustive minimum of the summed bound and, when the cap is
// short, the exhaustive minimax.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/allocation.hpp>

namespace {

using icd::mesh::allocate_children;
using icd::mesh::AllocationOptions;
using icd::mesh::ChildCountCosts;

/// Random costs, any shape (worst and sum not monotone in k).
std::vector<ChildCountCosts> random_costs(std::mt19937& rng, int parents, int max_size) {
  std::uniform_int_distribution<int> size(1, max_size);
  std::uniform_real_distribution<double> u(0, 100);
  std::vector<ChildCountCosts> costs(static_cast<size_t>(parents));
  for (auto& c : costs) {
    const int n = size(rng);
    for (int k = 0; k < n; ++k) c.worst.push_back(u(rng)), c.sum.push_back(u(rng) * (k + 1));
  }
  return costs;
}

/// Costs whose worst bound falls with k and whose summed bound falls convexly
/// (each extra child saves less than the one before).
std::vector<ChildCountCosts> convex_costs(std::mt19937& rng, int parents, int max_size) {
  std::uniform_int_distribution<int> size(1, max_size);
  std::uniform_real_distribution<double> u(0.05, 1);
  std::vector<ChildCountCosts> costs(static_cast<size_t>(parents));
  for (auto& c : costs) {
    const int n = size(rng);
    double worst = 100 * u(rng), sum = 200 * u(rng), drop = sum * 0.5 * u(rng);
    for (int k = 0; k < n; ++k) {
      c.worst.push_back(worst);
      c.sum.push_back(sum);
      worst *= u(rng);
      sum -= drop;
      drop *= 0.5 * u(rng);  // the drops sum to less than 2 drop <= sum: sums stay >= 0
    }
  }
  return costs;
}

/// Calls visit(count) for every allocation with 1 <= count[p] <= size and sum <= cap.
void for_each_allocation(const std::vector<ChildCountCosts>& costs, long long cap,
                         const std::function<void(const std::vector<int>&)>& visit) {
  std::vector<int> count(costs.size(), 1);
  std::function<void(size_t, long long)> rec = [&](size_t p, long long used) {
    if (p == costs.size()) {
      if (used <= cap) visit(count);
      return;
    }
    for (int k = 1; k <= static_cast<int>(costs[p].worst.size()); ++k) {
      count[p] = k;
      rec(p + 1, used + k);
    }
  };
  rec(0, 0);
}

double worst_of(const std::vector<ChildCountCosts>& costs, const std::vector<int>& count) {
  double w = 0;
  for (size_t p = 0; p < costs.size(); ++p)
    w = std::max(w, costs[p].worst[static_cast<size_t>(count[p] - 1)]);
  return w;
}

double sum_of(const std::vector<ChildCountCosts>& costs, const std::vector<int>& count) {
  double s = 0;
  for (size_t p = 0; p < costs.size(); ++p) s += costs[p].sum[static_cast<size_t>(count[p] - 1)];
  return s;
}

long long total_size(const std::vector<ChildCountCosts>& costs) {
  long long n = 0;
  for (const auto& c : costs) n += static_cast<long long>(c.worst.size());
  return n;
}

/// The fewest children with worst <= threshold (the size when none has).
int fewest_below(const ChildCountCosts& c, double threshold) {
  for (size_t k = 0; k < c.worst.size(); ++k)
    if (c.worst[k] <= threshold) return static_cast<int>(k + 1);
  return static_cast<int>(c.worst.size());
}

TEST(Allocation, FixedSplitSpendsTheCapWithinEachParentsConfigurations) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 200; ++trial) {
    const auto costs = random_costs(rng, 1 + trial % 7, 8);
    const auto n = static_cast<long long>(costs.size());
    const long long cap = std::uniform_int_distribution<long long>(0, 2 * total_size(costs))(rng);
    AllocationOptions o;
    o.worst_share = (trial % 5) / 4.0;
    const std::vector<int> count = allocate_children(costs, cap, o);
    ASSERT_EQ(count.size(), costs.size());
    for (size_t p = 0; p < costs.size(); ++p) {
      EXPECT_GE(count[p], 1);
      EXPECT_LE(count[p], static_cast<int>(costs[p].worst.size()));
    }
    EXPECT_EQ(std::accumulate(count.begin(), count.end(), 0LL),
              std::min(std::max(cap, n), total_size(costs)));
  }
}

TEST(Allocation, ThresholdRuleMeetsAFeasibleThresholdOnAnyCosts) {
  // Non-monotone costs: whenever the cap allows every parent its fewest
  // children with worst <= T (brute force), every parent for which such a
  // count exists ends at or below T, the others never above their worst at
  // that fewest count, and the cap is never exceeded.
  std::mt19937 rng(2);
  int exercised = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const auto costs = random_costs(rng, 1 + trial % 6, 8);
    AllocationOptions o;
    o.worst_threshold = std::uniform_real_distribution<double>(5, 80)(rng);
    long long needed = 0;
    for (const auto& c : costs) needed += fewest_below(c, o.worst_threshold);
    const long long cap = needed + std::uniform_int_distribution<long long>(0, 6)(rng);
    const std::vector<int> count = allocate_children(costs, cap, o);
    EXPECT_LE(std::accumulate(count.begin(), count.end(), 0LL), std::max<long long>(cap, 1));
    for (size_t p = 0; p < costs.size(); ++p) {
      const ChildCountCosts& c = costs[p];
      const double end = c.worst[static_cast<size_t>(count[p] - 1)];
      const int k = fewest_below(c, o.worst_threshold);
      if (c.worst[static_cast<size_t>(k - 1)] <= o.worst_threshold) {
        EXPECT_LE(end, o.worst_threshold) << "trial " << trial << " parent " << p;
        exercised += k > 1 ? 1 : 0;
      } else {
        EXPECT_LE(end, c.worst[static_cast<size_t>(k - 1)]) << "trial " << trial << " parent " << p;
      }
    }
  }
  EXPECT_GT(exercised, 100) << "the threshold must need more than one child often";
}

TEST(Allocation, ThresholdRuleReachesTheExhaustiveOptimumOnConvexCosts) {
  // Worst falling with k, summed bound convex: the threshold rule's summed
  // bound equals the smallest over every allocation within the cap that
  // meets the threshold (feasible cap), and its worst equals the exhaustive
  // minimax when the cap cannot meet it.
  std::mt19937 rng(3);
  int short_caps = 0, feasible_caps = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const auto costs = convex_costs(rng, 2 + trial % 3, 5);
    AllocationOptions o;
    o.worst_threshold = std::uniform_real_distribution<double>(2, 60)(rng);
    const long long cap = std::uniform_int_distribution<long long>(
        static_cast<long long>(costs.size()), total_size(costs))(rng);
    const std::vector<int> count = allocate_children(costs, cap, o);
    double best_sum = std::numeric_limits<double>::infinity();
    double best_worst = std::numeric_limits<double>::infinity();
    for_each_allocation(costs, cap, [&](const std::vector<int>& c) {
      const double w = worst_of(costs, c);
      best_worst = std::min(best_worst, w);
      if (w <= o.worst_threshold) best_sum = std::min(best_sum, sum_of(costs, c));
    });
    if (std::isfinite(best_sum)) {
      ++feasible_caps;
      EXPECT_LE(worst_of(costs, count), o.worst_threshold) << "trial " << trial;
      EXPECT_NEAR(sum_of(costs, count), best_sum, 1e-9 * (1 + best_sum)) << "trial " << trial;
    } else {
      ++short_caps;
      EXPECT_DOUBLE_EQ(worst_of(costs, count), best_worst) << "trial " << trial;
    }
  }
  EXPECT_GT(feasible_caps, 20);
  EXPECT_GT(short_caps, 20);
}

TEST(Allocation, RejectsBadCostsAndOptions) {
  const std::vector<ChildCountCosts> good{{{3, 2}, {3, 4}}};
  EXPECT_NO_THROW(allocate_children(good, 2, {}));
  AllocationOptions o;
  o.worst_share = 1.5;
  EXPECT_THROW(allocate_children(good, 2, o), icd::ParameterError);
  o = {};
  o.worst_threshold = -1;
  EXPECT_THROW(allocate_children(good, 2, o), icd::ParameterError);
  EXPECT_THROW(allocate_children({{{}, {}}}, 2, {}), icd::ParameterError);
  EXPECT_THROW(allocate_children({{{1, 2}, {1}}}, 2, {}), icd::ParameterError);
  EXPECT_THROW(allocate_children({{{1, std::nan("")}, {1, 2}}}, 2, {}), icd::ParameterError);
  EXPECT_THROW(allocate_children({{{1}, {-1}}}, 2, {}), icd::ParameterError);
}

}  // namespace
