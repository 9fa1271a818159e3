#include <icd/mesh/spheres/allocation.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <queue>
#include <string>
#include <utility>

#include <icd/mesh/core/error.hpp>

namespace icd::mesh {
namespace {

void check_input(const std::vector<ChildCountCosts>& costs, const AllocationOptions& options) {
  const std::string where = "allocate_children: ";
  if (!(options.worst_share >= 0 && options.worst_share <= 1))
    throw ParameterError(where + "worst_share must be in [0, 1]");
  if (!(options.worst_threshold >= 0)) throw ParameterError(where + "worst_threshold must be >= 0");
  for (size_t p = 0; p < costs.size(); ++p) {
    const ChildCountCosts& c = costs[p];
    if (c.worst.empty() || c.worst.size() != c.sum.size())
      throw ParameterError(where + "parent " + std::to_string(p) +
                           " needs equally many (>= 1) worst and summed costs");
    for (size_t k = 0; k < c.worst.size(); ++k) {
      if (!(c.worst[k] >= 0) || !(c.sum[k] >= 0))
        throw ParameterError(where + "parent " + std::to_string(p) + ", " + std::to_string(k + 1) +
                             " children: costs must be >= 0 (and not NaN)");
    }
  }
}

int max_count(const ChildCountCosts& c) { return static_cast<int>(c.worst.size()); }

/// The fixed split (today's rule): sum drop for the first (1 - worst_share)
/// of the extra spheres, then the worst child bound.
void allocate_fixed_split(const std::vector<ChildCountCosts>& costs, long long extra,
                          double worst_share, std::vector<int>& count) {
  const auto by_worst =
      static_cast<long long>(std::llround(worst_share * static_cast<double>(extra)));
  auto run = [&](long long n, bool worst_rule) {
    auto gain = [&](size_t p) {
      const int k = count[p];
      const ChildCountCosts& c = costs[p];
      if (k >= max_count(c)) return -1.0;
      if (worst_rule) return c.worst[static_cast<size_t>(k - 1)];
      return c.sum[static_cast<size_t>(k - 1)] - c.sum[static_cast<size_t>(k)];
    };
    std::priority_queue<std::pair<double, size_t>> heap;
    for (size_t p = 0; p < costs.size(); ++p) heap.emplace(gain(p), p);
    while (n > 0 && !heap.empty()) {
      const size_t p = heap.top().second;
      heap.pop();
      if (count[p] >= max_count(costs[p])) continue;
      count[p] += 1;
      --n;
      heap.emplace(gain(p), p);
    }
  };
  run(extra - by_worst, false);
  run(by_worst, true);
}

/// The threshold rule (AllocationOptions::worst_threshold).
void allocate_with_threshold(const std::vector<ChildCountCosts>& costs, long long extra,
                             double threshold, std::vector<int>& count) {
  // 1. The parent with the largest worst bound above the threshold gets a child.
  std::priority_queue<std::pair<double, size_t>> worst_heap;
  for (size_t p = 0; p < costs.size(); ++p) worst_heap.emplace(costs[p].worst[0], p);
  while (extra > 0 && !worst_heap.empty()) {
    const auto [w, p] = worst_heap.top();
    if (w <= threshold) break;
    worst_heap.pop();
    if (count[p] >= max_count(costs[p])) continue;
    count[p] += 1;
    --extra;
    worst_heap.emplace(costs[p].worst[static_cast<size_t>(count[p] - 1)], p);
  }
  // 2. The rest by summed drop per sphere, never above max(threshold, worst now).
  struct Step {
    double gain = 0;  // summed drop per sphere
    int to = 0;       // the child count after the step (0: none)
  };
  auto next_step = [&](size_t p) {
    const ChildCountCosts& c = costs[p];
    const int k = count[p];
    const double limit = std::max(threshold, c.worst[static_cast<size_t>(k - 1)]);
    for (int to = k + 1; to <= max_count(c); ++to) {
      if (c.worst[static_cast<size_t>(to - 1)] <= limit) {
        const double drop = c.sum[static_cast<size_t>(k - 1)] - c.sum[static_cast<size_t>(to - 1)];
        return Step{drop / (to - k), to};
      }
    }
    return Step{};
  };
  std::priority_queue<std::pair<double, size_t>> heap;
  for (size_t p = 0; p < costs.size(); ++p) {
    const Step s = next_step(p);
    if (s.to > 0) heap.emplace(s.gain, p);
  }
  while (extra > 0 && !heap.empty()) {
    const size_t p = heap.top().second;
    heap.pop();
    const Step s = next_step(p);
    if (s.to == 0) continue;
    if (s.to - count[p] > extra) continue;  // too many spheres for what is left
    extra -= s.to - count[p];
    count[p] = s.to;
    const Step again = next_step(p);
    if (again.to > 0) heap.emplace(again.gain, p);
  }
}

}  // namespace

std::vector<int> allocate_children(const std::vector<ChildCountCosts>& costs, long long cap,
                                   const AllocationOptions& options) {
  check_input(costs, options);
  std::vector<int> count(costs.size(), 1);
  const long long extra = std::max<long long>(0, cap - static_cast<long long>(costs.size()));
  if (options.worst_threshold > 0)
    allocate_with_threshold(costs, extra, options.worst_threshold, count);
  else
    allocate_fixed_split(costs, extra, options.worst_share, count);
  for (size_t p = 0; p < costs.size(); ++p)
    assert(count[p] >= 1 && count[p] <= max_count(costs[p]));
  return count;
}

}  // namespace icd::mesh
