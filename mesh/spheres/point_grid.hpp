#pragma once
/// A uniform grid over a fixed point set, for ball queries.
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Buckets the rows of P (#P x 3) in cubic cells of side `cell_size` (> 0),
/// stored as a dense cell array over the points' bounding box (compressed
/// rows; the cell side is enlarged when the box would need more than
/// max(4 #P, 2^20) cells, which changes no query result). The grid keeps a
/// reference to nothing: it copies the points it needs.
class PointGrid {
 public:
  /// Builds the grid. Throws ParameterError for a non-positive cell size.
  PointGrid(const Eigen::Ref<const MatX3d>& P, double cell_size);

  /// Indices of the points p with |p - center| <= radius, in increasing order.
  std::vector<int> query_ball(const Eigen::Vector3d& center, double radius) const;

  /// Index of the point nearest to q, or -1 when the grid is empty.
  int nearest(const Eigen::Vector3d& q) const;

  /// Number of points.
  int size() const { return static_cast<int>(m_by_cell.size()); }

 private:
  size_t linear(int i, int j, int k) const;
  /// Calls f(t) for every cell-order position t whose point lies in the ball.
  template <class F>
  void scan_ball(const Eigen::Vector3d& center, double radius, F&& f) const;
  /// Cell of p, each coordinate clamped to [-1, dims].
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const;

  double m_cell;
  Eigen::Vector3d m_origin = Eigen::Vector3d::Zero();  // lowest corner of cell (0, 0, 0)
  int m_dims[3] = {0, 0, 0};                           // cells per axis
  // Points of cell c: positions m_start[c] .. m_start[c + 1] - 1 of the two
  // arrays below, which hold them in cell order, so that scans read in order.
  std::vector<int> m_start;
  std::vector<int> m_index;                // the point's row in P
  std::vector<Eigen::Vector3d> m_by_cell;  // the point
};

}  // namespace icd::mesh
