#include <icd/mesh/spheres/sum_exchange.hpp>

#include <algorithm>
#include <map>
#include <numeric>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/sort_indices.hpp>

namespace icd::mesh {

int lower_error_sum(const ReductionProblem& problem, std::vector<FittedSphere>& spheres,
                    double max_error, const SumExchangeOptions& options,
                    const std::function<bool(int, int)>& accepts) {
  if (options.passes < 0 || !(options.cap_fraction > 0 && options.cap_fraction <= 1)) {
    throw ParameterError("SumExchangeOptions: passes must be >= 0 and cap_fraction in (0, 1]");
  }
  const int n = static_cast<int>(spheres.size());
  int moved_total = 0;
  for (int pass = 0; pass < options.passes; ++pass) {
    std::vector<int> order(static_cast<size_t>(n));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return spheres[static_cast<size_t>(a)].error > spheres[static_cast<size_t>(b)].error;
    });
    int moved_pass = 0;
    for (int a : order) {
      FittedSphere& A = spheres[static_cast<size_t>(a)];
      if (A.members.size() <= 1) continue;
      const double threshold = A.radius - options.cap_fraction * std::max(A.error, 0.0);
      std::vector<int> cap, rest;
      double new_radius = 0;
      for (int s : A.members) {
        const double r = problem.reach(s, A);
        if (r > threshold) {
          cap.push_back(s);
        } else {
          rest.push_back(s);
          new_radius = std::max(new_radius, r);
        }
      }
      if (rest.empty() || cap.empty()) continue;
      std::vector<int> neighbours;
      for (int b = 0; b < n; ++b) {
        const FittedSphere& B = spheres[static_cast<size_t>(b)];
        if (b != a && !B.members.empty() && (A.center - B.center).norm() <= A.radius + B.radius)
          neighbours.push_back(b);
      }
      // Each cap sample to the neighbour whose planned radius grows least.
      std::map<int, double> planned;  // receiver -> radius after receiving
      std::vector<int> receiver_of(cap.size(), -1);
      bool possible = true;
      for (size_t i = 0; i < cap.size() && possible; ++i) {
        double best = 0;
        for (int b : neighbours) {
          const FittedSphere& B = spheres[static_cast<size_t>(b)];
          auto it = planned.find(b);
          const double current = it == planned.end() ? B.radius : it->second;
          const double growth = std::max(problem.reach(cap[i], B), current) - current;
          if ((receiver_of[i] < 0 || growth < best) && (!accepts || accepts(b, cap[i])))
            best = growth, receiver_of[i] = b;
        }
        if (receiver_of[i] < 0) {
          possible = false;
          break;
        }
        const FittedSphere& B = spheres[static_cast<size_t>(receiver_of[i])];
        auto [it, inserted] = planned.emplace(receiver_of[i], B.radius);
        it->second = std::max(it->second, problem.reach(cap[i], B));
      }
      if (!possible) continue;
      double growth = 0;
      for (const auto& [b, r] : planned) {
        const FittedSphere& B = spheres[static_cast<size_t>(b)];
        growth += r - B.radius;
        if (r - B.depth > max_error) possible = false;
      }
      if (!possible || !(growth < A.radius - new_radius)) continue;
      for (size_t i = 0; i < cap.size(); ++i)
        spheres[static_cast<size_t>(receiver_of[i])].members.push_back(cap[i]);
      for (const auto& [b, r] : planned) {
        FittedSphere& B = spheres[static_cast<size_t>(b)];
        sort_indices(B.members);
        B.radius = r;
        B.error = r - B.depth;
      }
      A.members = std::move(rest);
      A.radius = new_radius;
      A.error = new_radius - A.depth;
      ++moved_pass;
    }
    moved_total += moved_pass;
    if (moved_pass == 0) break;
  }
  return moved_total;
}

}  // namespace icd::mesh
