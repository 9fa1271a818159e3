#pragma once
/// Axis-aligned bounding-box tree over the triangles of a dense mesh, for the
/// exact reference: all intersecting triangle pairs between two meshes.
#include <utility>
#include <vector>

#include <icd/mesh/core/types.hpp>

namespace icd::collision {

/// A bounding-box hierarchy over triangles (binary, median split on the
/// longest axis of the centroids, at most `leaf_size` triangles per leaf).
class AabbTree {
 public:
  /// One node: box, children (-1 for a leaf) and, for a leaf, a range of
  /// m_order (the triangle indices it holds).
  struct Node {
    Eigen::Vector3d lo, hi;
    int left = -1, right = -1;
    int begin = 0, end = 0;
  };

  AabbTree() = default;
  /// Builds the tree over the triangles F (#F x 3) of vertex positions V (#V x 3).
  /// Throws InputError for out-of-range indices or non-finite vertices.
  AabbTree(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F, int leaf_size = 4);

  /// Recomputes every box bottom-up for new positions V (same topology).
  void refit(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F);

  const std::vector<Node>& nodes() const { return m_nodes; }
  const std::vector<int>& order() const { return m_order; }

 private:
  int build(const std::vector<Eigen::Vector3d>& centroids, const Eigen::Ref<const MatX3d>& V,
            const Eigen::Ref<const MatX3i>& F, int begin, int end, int leaf_size);
  std::vector<Node> m_nodes;
  std::vector<int> m_order;
};

/// All pairs (f, g), f a triangle of (V1, F1), g of (V2, F2), that intersect
/// (closed triangles, exact test), found through the two trees (built on
/// these positions or refitted to them). Sorted.
std::vector<std::pair<int, int>> intersecting_triangle_pairs(
    const AabbTree& t1, const Eigen::Ref<const MatX3d>& V1, const Eigen::Ref<const MatX3i>& F1,
    const AabbTree& t2, const Eigen::Ref<const MatX3d>& V2, const Eigen::Ref<const MatX3i>& F2);

/// The same by testing every pair (#F1 x #F2 exact tests): the oracle for small meshes.
std::vector<std::pair<int, int>> intersecting_triangle_pairs_brute_force(
    const Eigen::Ref<const MatX3d>& V1, const Eigen::Ref<const MatX3i>& F1,
    const Eigen::Ref<const MatX3d>& V2, const Eigen::Ref<const MatX3i>& F2);

}  // namespace icd::collision
