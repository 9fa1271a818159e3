#pragma once
/// A uniform hash grid over a fixed point set, for ball queries.
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "mesh/io/types.hpp"

namespace icd::mesh {

/// Buckets the rows of P (#P x 3) in cubic cells of side `cell_size` (> 0).
/// The grid keeps a reference to nothing: it copies the points it needs.
class PointGrid {
 public:
  /// Builds the grid. Throws ParameterError for a non-positive cell size.
  PointGrid(const Eigen::Ref<const MatX3d>& P, double cell_size);

  /// Indices of the points p with |p - center| <= radius, in increasing order.
  std::vector<int> query_ball(const Eigen::Vector3d& center, double radius) const;

  /// Index of the point nearest to q, or -1 when the grid is empty.
  int nearest(const Eigen::Vector3d& q) const;

  /// Number of points.
  int size() const { return static_cast<int>(m_points.size()); }

 private:
  long long key(long long i, long long j, long long k) const;
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const;

  double m_cell;
  std::vector<Eigen::Vector3d> m_points;
  std::vector<Eigen::Vector3i> m_point_cells;  // cell of each point (hash-collision check)
  std::unordered_map<long long, std::vector<int>> m_cells;
  Eigen::Vector3i m_min_cell{0, 0, 0}, m_max_cell{0, 0, 0};
};

}  // namespace icd::mesh
