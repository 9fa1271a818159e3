#include <icd/mesh/spheres/regroup.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::mesh {
namespace {

/// The radius parent p needs for its children `kids` with child `out`
/// removed (-1: none) and child `in` added (-1: none).
double radius_of(const std::vector<std::vector<double>>& reach, const std::vector<int>& kids, int p,
                 int out, int in) {
  double r = 0;
  for (int i : kids) {
    if (i != out) r = std::max(r, reach[static_cast<size_t>(i)][static_cast<size_t>(p)]);
  }
  if (in >= 0) r = std::max(r, reach[static_cast<size_t>(in)][static_cast<size_t>(p)]);
  return r;
}

}  // namespace

double regroup_cost(const std::vector<std::vector<double>>& reach, const std::vector<int>& parent,
                    int num_parents) {
  std::vector<double> radius(static_cast<size_t>(num_parents), 0.0);
  for (size_t i = 0; i < parent.size(); ++i) {
    const auto p = static_cast<size_t>(parent[i]);
    radius[p] = std::max(radius[p], reach[i][p]);
  }
  double sum = 0;
  for (double r : radius) sum += r;
  return sum;
}

std::vector<int> regroup_children(const std::vector<std::vector<double>>& reach,
                                  std::vector<int> parent, int capacity, int max_improvements) {
  const size_t n = parent.size();
  if (reach.size() != n)
    throw ParameterError("regroup_children: reach must have one row per child");
  const size_t m = n == 0 ? 0 : reach.front().size();
  for (const auto& row : reach) {
    if (row.size() != m) throw ParameterError("regroup_children: reach rows differ in length");
    for (double r : row) {
      if (!(r >= 0) || !std::isfinite(r))
        throw ParameterError("regroup_children: reach entries must be finite and >= 0");
    }
  }
  if (capacity < 1) throw ParameterError("regroup_children: capacity must be >= 1");
  if (n > m * static_cast<size_t>(capacity)) {
    throw ParameterError("regroup_children: " + std::to_string(n) + " children do not fit under " +
                         std::to_string(m) + " parents of " + std::to_string(capacity));
  }
  std::vector<std::vector<int>> kids(m);
  for (size_t i = 0; i < n; ++i) {
    if (parent[i] < 0 || static_cast<size_t>(parent[i]) >= m)
      throw ParameterError("regroup_children: parent index out of range");
    kids[static_cast<size_t>(parent[i])].push_back(static_cast<int>(i));
  }
  std::vector<double> radius(m);
  for (size_t p = 0; p < m; ++p) radius[p] = radius_of(reach, kids[p], static_cast<int>(p), -1, -1);
  auto move = [&](int i, int q) {
    const auto p = static_cast<size_t>(parent[static_cast<size_t>(i)]);
    kids[p].erase(std::find(kids[p].begin(), kids[p].end(), i));
    kids[static_cast<size_t>(q)].push_back(i);
    parent[static_cast<size_t>(i)] = q;
    radius[p] = radius_of(reach, kids[p], static_cast<int>(p), -1, -1);
    radius[static_cast<size_t>(q)] = radius_of(reach, kids[static_cast<size_t>(q)], q, -1, -1);
  };

  // Repair: an overfull parent passes a child along the cheapest chain of
  // parents to one with room; each step moves the child of the giving parent
  // whose move raises the receiver's radius least (Dijkstra over the parents,
  // edge weight = that rise).
  auto cheapest = [&](size_t a, size_t b, int* child) {
    double best = 0;
    *child = -1;
    for (int i : kids[a]) {
      const double rise = std::max(radius[b], reach[static_cast<size_t>(i)][b]) - radius[b];
      if (*child < 0 || rise < best) best = rise, *child = i;
    }
    return best;
  };
  for (size_t p = 0; p < m; ++p) {
    while (kids[p].size() > static_cast<size_t>(capacity)) {
      std::vector<double> dist(m, std::numeric_limits<double>::infinity());
      std::vector<int> from(m, -1);
      std::vector<char> done(m, 0);
      dist[p] = 0;
      int target = -1;
      for (;;) {
        int a = -1;
        for (size_t q = 0; q < m; ++q) {
          if (!done[q] && std::isfinite(dist[q]) &&
              (a < 0 || dist[q] < dist[static_cast<size_t>(a)]))
            a = static_cast<int>(q);
        }
        if (a < 0) break;
        done[static_cast<size_t>(a)] = 1;
        if (static_cast<size_t>(a) != p &&
            kids[static_cast<size_t>(a)].size() < static_cast<size_t>(capacity)) {
          target = a;
          break;
        }
        // A parent on the chain gives one child and receives one: it needs a child to give.
        if (kids[static_cast<size_t>(a)].empty()) continue;
        for (size_t b = 0; b < m; ++b) {
          if (done[b]) continue;
          int child = -1;
          const double d =
              dist[static_cast<size_t>(a)] + cheapest(static_cast<size_t>(a), b, &child);
          if (d < dist[b]) dist[b] = d, from[b] = a;
        }
      }
      // Every other parent is one step from p, and one has room when n <= m * capacity.
      if (target < 0) throw std::logic_error("regroup_children: no parent with room");
      // Moves along the chain, from its end back to p (each giver still has its child).
      std::vector<int> chain{target};
      while (static_cast<size_t>(chain.back()) != p)
        chain.push_back(from[static_cast<size_t>(chain.back())]);
      for (size_t k = 0; k + 1 < chain.size(); ++k) {
        const auto b = static_cast<size_t>(chain[k]), a = static_cast<size_t>(chain[k + 1]);
        int child = -1;
        cheapest(a, b, &child);
        move(child, static_cast<int>(b));
      }
    }
  }

  // Improvement: only a parent's farthest child can lower its radius, so every
  // improving move or swap takes one; first improvement, sweeps until none.
  double total = 0;
  for (double r : radius) total += r;
  const double tolerance = 1e-12 * std::max(1.0, total);
  int improvements = 0;
  bool any = true;
  while (any && improvements < max_improvements) {
    any = false;
    for (size_t p = 0; p < m && improvements < max_improvements; ++p) {
      if (kids[p].empty()) continue;
      int far = kids[p].front();
      for (int i : kids[p]) {
        if (reach[static_cast<size_t>(i)][p] > reach[static_cast<size_t>(far)][p]) far = i;
      }
      const double without = radius_of(reach, kids[p], static_cast<int>(p), far, -1);
      bool done = false;
      for (size_t q = 0; q < m && !done; ++q) {
        if (q == p) continue;
        if (kids[q].size() < static_cast<size_t>(capacity) && kids[p].size() > 1 &&
            without + std::max(radius[q], reach[static_cast<size_t>(far)][q]) - radius[p] -
                    radius[q] <
                -tolerance) {
          move(far, static_cast<int>(q));
          done = true;
          break;
        }
        for (int j : kids[q]) {
          const double rp = radius_of(reach, kids[p], static_cast<int>(p), far, j);
          const double rq = radius_of(reach, kids[q], static_cast<int>(q), j, far);
          if (rp + rq - radius[p] - radius[q] < -tolerance) {
            move(far, static_cast<int>(q));
            move(j, static_cast<int>(p));
            done = true;
            break;
          }
        }
      }
      if (done) ++improvements, any = true;
    }
  }
  return parent;
}

}  // namespace icd::mesh
