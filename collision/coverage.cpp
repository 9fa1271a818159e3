#include <icd/collision/coverage.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include <icd/mesh/core/error.hpp>

namespace icd::collision {

CoverageReport measure_coverage(const SphereTree& tree, const Eigen::Ref<const MatX3d>& P,
                                int level) {
  if (level < -1 || level >= tree.num_levels())
    throw ParameterError("measure_coverage: level " + std::to_string(level) + " outside [-1, " +
                         std::to_string(tree.num_levels()) + ")");
  std::vector<int> cut;
  for (int i = 0; i < tree.num_nodes(); ++i) {
    const bool in_cut =
        level < 0 ? tree.is_leaf(i)
                  : (tree.level[i] == level || (tree.level[i] < level && tree.is_leaf(i)));
    if (in_cut) cut.push_back(i);
  }
  CoverageReport rep;
  rep.num_points = static_cast<int>(P.rows());
  if (P.rows() == 0) return rep;
  // Grid cell size: the median sphere diameter of the cut.
  std::vector<double> radii;
  for (int i : cut) radii.push_back(tree.spheres[i].r);
  std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
  const double h = std::max(2.0 * radii[radii.size() / 2], 1e-12);
  auto key = [](long long a, long long b, long long c) {
    return (a * 73856093LL) ^ (b * 19349663LL) ^ (c * 83492791LL);
  };
  std::unordered_map<long long, std::vector<int>> grid;
  const long long max_cells_per_sphere = 4096;
  std::vector<int> big;  // spheres spanning too many cells: tested against every point
  for (int i : cut) {
    const Sphere& s = tree.spheres[i];
    const long long x0 = std::floor((s.x - s.r) / h), x1 = std::floor((s.x + s.r) / h);
    const long long y0 = std::floor((s.y - s.r) / h), y1 = std::floor((s.y + s.r) / h);
    const long long z0 = std::floor((s.z - s.r) / h), z1 = std::floor((s.z + s.r) / h);
    if ((x1 - x0 + 1) * (y1 - y0 + 1) * (z1 - z0 + 1) > max_cells_per_sphere) {
      big.push_back(i);
      continue;
    }
    for (long long a = x0; a <= x1; ++a)
      for (long long b = y0; b <= y1; ++b)
        for (long long c = z0; c <= z1; ++c) grid[key(a, b, c)].push_back(i);
  }
  auto inside = [&](int i, const Eigen::Vector3d& p) {
    const Sphere& s = tree.spheres[i];
    return (p - s.center()).squaredNorm() <= s.r * s.r;
  };
  for (int v = 0; v < P.rows(); ++v) {
    const Eigen::Vector3d p = P.row(v).transpose();
    bool covered = false;
    auto it = grid.find(key(std::floor(p.x() / h), std::floor(p.y() / h), std::floor(p.z() / h)));
    if (it != grid.end())
      for (int i : it->second)
        if (inside(i, p)) {
          covered = true;
          break;
        }
    for (std::size_t k = 0; k < big.size() && !covered; ++k) covered = inside(big[k], p);
    if (covered) continue;
    ++rep.num_uncovered;
    double gap = std::numeric_limits<double>::infinity();
    for (int i : cut)
      gap = std::min(gap, (p - tree.spheres[i].center()).norm() - tree.spheres[i].r);
    rep.max_gap = std::max(rep.max_gap, gap);
  }
  rep.uncovered_fraction = double(rep.num_uncovered) / double(rep.num_points);
  return rep;
}

}  // namespace icd::collision
