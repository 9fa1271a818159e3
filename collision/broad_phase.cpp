#include <icd/collision/broad_phase.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::collision {

std::vector<std::pair<int, int>> sweep_and_prune(const std::vector<Sphere>& bounds) {
  const int n = static_cast<int>(bounds.size());
  for (int i = 0; i < n; ++i) {
    const Sphere& s = bounds[i];
    if (!std::isfinite(s.x) || !std::isfinite(s.y) || !std::isfinite(s.z) || !std::isfinite(s.r) ||
        s.r < 0)
      throw ParameterError("sweep_and_prune: object " + std::to_string(i) +
                           " has a non-finite sphere or a negative radius");
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    const double la = bounds[a].x - bounds[a].r, lb = bounds[b].x - bounds[b].r;
    return la < lb || (la == lb && a < b);
  });
  std::vector<std::pair<int, int>> out;
  std::vector<int> active;  // objects whose x interval may still overlap
  for (int idx : order) {
    const Sphere& s = bounds[idx];
    const double lo = s.x - s.r;
    std::size_t keep = 0;
    for (int other : active) {
      const Sphere& o = bounds[other];
      if (o.x + o.r < lo) continue;  // ended before this one starts: drop
      active[keep++] = other;
      if (overlap(s, o)) out.push_back({std::min(idx, other), std::max(idx, other)});
    }
    active.resize(keep);
    active.push_back(idx);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::pair<int, int>> all_pairs_overlapping(const std::vector<Sphere>& bounds) {
  std::vector<std::pair<int, int>> out;
  for (int i = 0; i < static_cast<int>(bounds.size()); ++i)
    for (int j = i + 1; j < static_cast<int>(bounds.size()); ++j)
      if (overlap(bounds[i], bounds[j])) out.push_back({i, j});
  return out;
}

std::vector<Sphere> root_spheres(const std::vector<const SphereTree*>& trees) {
  std::vector<Sphere> s;
  s.reserve(trees.size());
  for (const SphereTree* t : trees) s.push_back(t->spheres.at(0));
  return s;
}

}  // namespace icd::collision
