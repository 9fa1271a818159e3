#include <icd/mesh/spheres/point_grid.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/sort_indices.hpp>

namespace icd::mesh {

PointGrid::PointGrid(const Eigen::Ref<const MatX3d>& P, double cell_size) : m_cell(cell_size) {
  if (!(cell_size > 0) || !std::isfinite(cell_size)) {
    throw ParameterError("PointGrid: cell_size must be positive and finite, got " +
                         std::to_string(cell_size));
  }
  const auto n = static_cast<size_t>(P.rows());
  if (n == 0) return;
  auto point = [&](size_t i) -> Eigen::Vector3d { return P.row(static_cast<Eigen::Index>(i)); };
  Eigen::Vector3d lo = point(0), hi = point(0);
  for (size_t i = 1; i < n; ++i) lo = lo.cwiseMin(point(i)), hi = hi.cwiseMax(point(i));
  // The cell size only affects speed (queries are exact): coarsen it so that
  // the dense cell array stays within a few cells per point.
  const double max_cells = std::max(4.0 * static_cast<double>(n), double{1 << 20});
  auto cells_for = [&](double cell) {
    double total = 1;
    for (int k = 0; k < 3; ++k) total *= std::floor((hi[k] - lo[k]) / cell) + 1;
    return total;
  };
  while (cells_for(m_cell) > max_cells) m_cell *= 1.25;
  m_origin = lo;
  for (int k = 0; k < 3; ++k)
    m_dims[k] = static_cast<int>(std::floor((hi[k] - lo[k]) / m_cell)) + 1;
  const auto num_cells = static_cast<size_t>(m_dims[0]) * static_cast<size_t>(m_dims[1]) *
                         static_cast<size_t>(m_dims[2]);
  // Counting sort of the points by cell (CSR); indices stay increasing per cell.
  std::vector<size_t> cell(n);
  m_start.assign(num_cells + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3i c = cell_of(point(i));
    cell[i] = linear(c.x(), c.y(), c.z());
    m_start[cell[i] + 1] += 1;
  }
  for (size_t c = 0; c < num_cells; ++c) m_start[c + 1] += m_start[c];
  m_index.resize(n);
  std::vector<int> fill(m_start.begin(), m_start.end() - 1);
  for (size_t i = 0; i < n; ++i)
    m_index[static_cast<size_t>(fill[cell[i]]++)] = static_cast<int>(i);
  m_by_cell.resize(n);
  for (size_t t = 0; t < n; ++t) m_by_cell[t] = point(static_cast<size_t>(m_index[t]));
}

size_t PointGrid::linear(int i, int j, int k) const {
  return (static_cast<size_t>(i) * static_cast<size_t>(m_dims[1]) + static_cast<size_t>(j)) *
             static_cast<size_t>(m_dims[2]) +
         static_cast<size_t>(k);
}

Eigen::Vector3i PointGrid::cell_of(const Eigen::Vector3d& p) const {
  Eigen::Vector3i c;
  for (int k = 0; k < 3; ++k) {
    const double x = std::floor((p[k] - m_origin[k]) / m_cell);
    c[k] = static_cast<int>(std::clamp(x, -1.0, static_cast<double>(m_dims[k])));
  }
  return c;
}

template <class F>
void PointGrid::scan_ball(const Eigen::Vector3d& center, double radius, F&& f) const {
  if (m_by_cell.empty() || !(radius >= 0)) return;
  const Eigen::Vector3i lo =
      cell_of(center - Eigen::Vector3d::Constant(radius)).cwiseMax(Eigen::Vector3i::Zero());
  const Eigen::Vector3i hi =
      cell_of(center + Eigen::Vector3d::Constant(radius))
          .cwiseMin(Eigen::Vector3i(m_dims[0] - 1, m_dims[1] - 1, m_dims[2] - 1));
  const double r2 = radius * radius;
  for (int i = lo.x(); i <= hi.x(); ++i) {
    for (int j = lo.y(); j <= hi.y(); ++j) {
      // Cells (i, j, lo.z .. hi.z) are contiguous in the CSR arrays.
      const int begin = m_start[linear(i, j, lo.z())], end = m_start[linear(i, j, hi.z()) + 1];
      for (int t = begin; t < end; ++t) {
        if ((m_by_cell[static_cast<size_t>(t)] - center).squaredNorm() <= r2)
          f(static_cast<size_t>(t));
      }
    }
  }
}

std::vector<int> PointGrid::query_ball(const Eigen::Vector3d& center, double radius) const {
  std::vector<int> out;
  scan_ball(center, radius, [&](size_t t) { out.push_back(m_index[t]); });
  // Increasing order: a sort for small results, a scan of flags over all
  // points for large ones (same output, linear time).
  if (out.size() * 16 < m_by_cell.size()) {
    sort_indices(out);
    return out;
  }
  std::vector<char> hit(m_by_cell.size(), 0);
  for (int idx : out) hit[static_cast<size_t>(idx)] = 1;
  size_t k = 0;
  for (size_t i = 0; i < hit.size(); ++i) {
    if (hit[i]) out[k++] = static_cast<int>(i);
  }
  return out;
}

int PointGrid::nearest(const Eigen::Vector3d& q) const {
  if (m_by_cell.empty()) return -1;
  // Distance from q to the grid's box, plus its diagonal: a ball of that
  // radius holds every point.
  double outside = 0;
  for (int k = 0; k < 3; ++k) {
    const double hi = m_origin[k] + m_cell * m_dims[k];
    const double d = std::max({m_origin[k] - q[k], q[k] - hi, 0.0});
    outside += d * d;
  }
  const Eigen::Vector3d extent(m_dims[0], m_dims[1], m_dims[2]);
  const double max_radius = std::sqrt(outside) + m_cell * extent.norm();
  double radius = std::max(m_cell, std::sqrt(outside) + m_cell);
  while (true) {
    // The nearest point in the ball; of equally near ones, the lowest index.
    int best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    scan_ball(q, radius, [&](size_t t) {
      const double d = (m_by_cell[t] - q).squaredNorm();
      if (d < best_d || (d == best_d && m_index[t] < best)) best_d = d, best = m_index[t];
    });
    if (best >= 0) return best;
    if (radius > max_radius) break;
    radius *= 2;
  }
  return -1;
}

}  // namespace icd::mesh
