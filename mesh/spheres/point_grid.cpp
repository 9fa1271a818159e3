#include "mesh/spheres/point_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "mesh/io/error.hpp"

namespace icd::mesh {

PointGrid::PointGrid(const Eigen::Ref<const MatX3d>& P, double cell_size) : m_cell(cell_size) {
  if (!(cell_size > 0) || !std::isfinite(cell_size)) {
    throw ParameterError("PointGrid: cell_size must be positive and finite, got " +
                         std::to_string(cell_size));
  }
  m_points.resize(static_cast<size_t>(P.rows()));
  m_point_cells.resize(static_cast<size_t>(P.rows()));
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    m_points[static_cast<size_t>(i)] = P.row(i);
    const Eigen::Vector3i c = cell_of(m_points[static_cast<size_t>(i)]);
    m_point_cells[static_cast<size_t>(i)] = c;
    if (i == 0) {
      m_min_cell = m_max_cell = c;
    } else {
      m_min_cell = m_min_cell.cwiseMin(c);
      m_max_cell = m_max_cell.cwiseMax(c);
    }
    m_cells[key(c.x(), c.y(), c.z())].push_back(static_cast<int>(i));
  }
}

long long PointGrid::key(long long i, long long j, long long k) const {
  return (i * 73856093LL) ^ (j * 19349663LL) ^ (k * 83492791LL);
}

Eigen::Vector3i PointGrid::cell_of(const Eigen::Vector3d& p) const {
  return {static_cast<int>(std::floor(p.x() / m_cell)),
          static_cast<int>(std::floor(p.y() / m_cell)),
          static_cast<int>(std::floor(p.z() / m_cell))};
}

std::vector<int> PointGrid::query_ball(const Eigen::Vector3d& center, double radius) const {
  std::vector<int> out;
  if (m_points.empty() || radius < 0) return out;
  const Eigen::Vector3i lo =
      cell_of(center - Eigen::Vector3d::Constant(radius)).cwiseMax(m_min_cell);
  const Eigen::Vector3i hi =
      cell_of(center + Eigen::Vector3d::Constant(radius)).cwiseMin(m_max_cell);
  const double r2 = radius * radius;
  for (int i = lo.x(); i <= hi.x(); ++i) {
    for (int j = lo.y(); j <= hi.y(); ++j) {
      for (int k = lo.z(); k <= hi.z(); ++k) {
        auto it = m_cells.find(key(i, j, k));
        if (it == m_cells.end()) continue;
        for (int idx : it->second) {
          const Eigen::Vector3i& c = m_point_cells[static_cast<size_t>(idx)];
          if (c.x() != i || c.y() != j || c.z() != k) continue;  // hash collision
          if ((m_points[static_cast<size_t>(idx)] - center).squaredNorm() <= r2) out.push_back(idx);
        }
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

int PointGrid::nearest(const Eigen::Vector3d& q) const {
  if (m_points.empty()) return -1;
  double radius = m_cell;
  const double max_radius = m_cell * (2.0 + (m_max_cell - m_min_cell).cast<double>().norm()) +
                            (q - m_points.front()).norm();
  while (true) {
    const std::vector<int> near = query_ball(q, radius);
    if (!near.empty()) {
      int best = near.front();
      double best_d = std::numeric_limits<double>::infinity();
      for (int idx : near) {
        const double d = (m_points[static_cast<size_t>(idx)] - q).squaredNorm();
        if (d < best_d) best_d = d, best = idx;
      }
      return best;
    }
    if (radius > max_radius) break;
    radius *= 2;
  }
  return -1;
}

}  // namespace icd::mesh
