#pragma once
/// Closest-point queries on a triangle soup through a bounding-volume
/// hierarchy of axis-aligned boxes (no CGAL: the builder's hot loops call it).
#include <vector>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Static BVH over the triangles F (#F x 3) of V (#V x 3): median splits
/// along the longest box axis, at most 4 triangles per leaf. Queries visit
/// the nearer child first and skip boxes farther than the best distance so
/// far. Deterministic; concurrent const queries are safe.
class TriangleBvh {
 public:
  /// Builds the hierarchy. Throws InputError for an empty mesh or an
  /// out-of-range vertex index.
  TriangleBvh(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F);

  /// Closest point of the triangles to p, and the index (row of F) of the
  /// triangle it lies on (the lowest index among equally near ones is not
  /// guaranteed: any nearest triangle).
  struct Hit {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< closest surface point
    double squared_distance = 0;                      ///< |p - point|^2 (model units^2)
    int face = -1;                                    ///< triangle of `point`
  };
  /// The closest point of the surface to p (exact up to rounding).
  Hit closest(const Eigen::Vector3d& p) const;

  /// Unsigned distance from p to the surface (model units).
  double distance(const Eigen::Vector3d& p) const;

 private:
  struct Node {
    double lo[3], hi[3];
    int first;  // leaf: first triangle (BVH position); inner: index of the left child
    int count;  // leaf: number of triangles (> 0); inner: 0
    int right;  // inner: index of the right child
  };
  int build(int begin, int end, int depth);

  std::vector<Node> m_nodes;
  std::vector<Eigen::Vector3d> m_corner;  // 3 corners per triangle, in BVH order
  std::vector<int> m_order;               // BVH position -> row of F
  std::vector<Eigen::Vector3d> m_centroid;
};

}  // namespace icd::mesh
