#include <icd/mesh/spheres/exchange.hpp>

#include <algorithm>
#include <numeric>
#include <set>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/sort_indices.hpp>

namespace icd::mesh {

int shrink_by_exchange(const ReductionProblem& problem, std::vector<FittedSphere>& spheres,
                       const ExchangeOptions& options,
                       const std::function<bool(int, int)>& accepts) {
  if (options.rounds < 0 || options.max_moves_per_sphere < 1) {
    throw ParameterError("ExchangeOptions: rounds must be >= 0 and max_moves_per_sphere >= 1");
  }
  const int n = static_cast<int>(spheres.size());
  int moved_total = 0;
  for (int round = 0; round < options.rounds; ++round) {
    // Spheres that overlap (only they can hold a sample of each other).
    std::vector<std::vector<int>> overlapping(static_cast<size_t>(n));
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        const auto& A = spheres[static_cast<size_t>(a)];
        const auto& B = spheres[static_cast<size_t>(b)];
        if (a != b && (A.center - B.center).norm() <= A.radius + B.radius)
          overlapping[static_cast<size_t>(a)].push_back(b);
      }
    }
    std::vector<int> order(static_cast<size_t>(n));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return spheres[static_cast<size_t>(a)].error > spheres[static_cast<size_t>(b)].error;
    });
    int moved_round = 0;
    for (int j : order) {
      FittedSphere& sp = spheres[static_cast<size_t>(j)];
      // Samples received earlier in this pass were appended: restore the order.
      sort_indices(sp.members);
      if (sp.members.size() <= 1) continue;
      // Members farthest first, popped lazily from a heap (most never leave).
      std::vector<std::pair<double, int>> heap;
      heap.reserve(sp.members.size());
      for (int s : sp.members)
        heap.emplace_back(problem.reach(s, sp), -s);  // ties: smaller index first
      std::make_heap(heap.begin(), heap.end());
      std::vector<int> leaving;
      while (heap.size() > 1 && static_cast<int>(leaving.size()) < options.max_moves_per_sphere) {
        const int s = -heap.front().second;
        int receiver = -1;
        for (int k : overlapping[static_cast<size_t>(j)]) {
          const FittedSphere& other = spheres[static_cast<size_t>(k)];
          if (problem.reach(s, other) <= other.radius && (!accepts || accepts(k, s))) {
            receiver = k;
            break;
          }
        }
        if (receiver < 0) break;
        leaving.push_back(s);
        spheres[static_cast<size_t>(receiver)].members.push_back(s);  // covered: its radius stands
        std::pop_heap(heap.begin(), heap.end());
        heap.pop_back();
      }
      const double farthest_kept = heap.front().first;
      if (leaving.empty()) continue;
      std::sort(leaving.begin(), leaving.end());
      std::vector<int> kept;
      std::set_difference(sp.members.begin(), sp.members.end(), leaving.begin(), leaving.end(),
                          std::back_inserter(kept));
      sp.members = std::move(kept);
      sp.radius = farthest_kept;
      sp.error = sp.radius - sp.depth;
      moved_round += static_cast<int>(leaving.size());
    }
    for (auto& other : spheres) {
      sort_indices(other.members);
    }
    moved_total += moved_round;
    if (moved_round == 0) break;
  }
  return moved_total;
}

int relieve_worst(const ReductionProblem& problem, std::vector<FittedSphere>& spheres,
                  int max_moves, const std::function<bool(int, int)>& accepts) {
  if (max_moves < 0) throw ParameterError("relieve_worst: max_moves must be >= 0");
  const int n = static_cast<int>(spheres.size());
  if (n < 2) return 0;
  // Per sphere: a max-heap of (reach, -sample) over its current members.
  std::vector<std::vector<std::pair<double, int>>> heaps(static_cast<size_t>(n));
  std::vector<int> size(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    auto& h = heaps[static_cast<size_t>(j)];
    for (int s : spheres[static_cast<size_t>(j)].members)
      h.emplace_back(problem.reach(s, spheres[static_cast<size_t>(j)]), -s);
    std::make_heap(h.begin(), h.end());
    size[static_cast<size_t>(j)] = static_cast<int>(h.size());
  }
  // Worst sphere first (ties: lower index).
  std::set<std::pair<double, int>> by_error;
  for (int j = 0; j < n; ++j) by_error.emplace(-spheres[static_cast<size_t>(j)].error, j);
  int moves = 0;
  while (moves < max_moves) {
    const int j = by_error.begin()->second;
    FittedSphere& worst = spheres[static_cast<size_t>(j)];
    auto& hj = heaps[static_cast<size_t>(j)];
    if (size[static_cast<size_t>(j)] <= 1) break;
    const int s = -hj.front().second;
    int receiver = -1;
    double receiver_error = worst.error;
    for (int k = 0; k < n; ++k) {
      if (k == j) continue;
      const FittedSphere& other = spheres[static_cast<size_t>(k)];
      const double r = std::max(other.radius, problem.reach(s, other));
      const double e = r - other.depth;
      if (e < receiver_error && (!accepts || accepts(k, s))) receiver_error = e, receiver = k;
    }
    if (receiver < 0) break;
    // Move s from j to the receiver.
    std::pop_heap(hj.begin(), hj.end());
    hj.pop_back();
    size[static_cast<size_t>(j)] -= 1;
    FittedSphere& other = spheres[static_cast<size_t>(receiver)];
    const double rs = problem.reach(s, other);
    auto& hk = heaps[static_cast<size_t>(receiver)];
    hk.emplace_back(rs, -s);
    std::push_heap(hk.begin(), hk.end());
    size[static_cast<size_t>(receiver)] += 1;
    by_error.erase({-worst.error, j});
    by_error.erase({-other.error, receiver});
    worst.radius = hj.front().first;
    worst.error = worst.radius - worst.depth;
    other.radius = std::max(other.radius, rs);
    other.error = other.radius - other.depth;
    by_error.emplace(-worst.error, j);
    by_error.emplace(-other.error, receiver);
    ++moves;
  }
  if (moves > 0) {
    for (int j = 0; j < n; ++j) {
      auto& members = spheres[static_cast<size_t>(j)].members;
      members.clear();
      for (const auto& [r, neg] : heaps[static_cast<size_t>(j)]) members.push_back(-neg);
      sort_indices(members);
    }
  }
  return moves;
}

}  // namespace icd::mesh
