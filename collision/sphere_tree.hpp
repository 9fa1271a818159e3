#pragma once
/// The runtime sphere tree: a flat, pointer-free, breadth-first array layout.
///
/// A *wrapped* hierarchy (paper 4.1): each level covers the object's surface;
/// a child need not lie inside its parent. Nodes are stored level by level
/// (breadth-first), the children of a node contiguous, so a node is an index.
/// The rest data that the BD-tree style update (paper 4.4) needs is stored
/// alongside: each node's associated coarse nodes V_i (CSR) and their rest
/// distances to the node's rest centre.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace icd::collision {

/// One sphere: centre (x, y, z) and radius r, in model units.
struct Sphere {
  double x = 0, y = 0, z = 0, r = 0;
  Eigen::Vector3d center() const { return {x, y, z}; }
};

/// Sphere tree in breadth-first order. Node 0 is the root.
/// Invariants (checked by validate()):
///  - spheres, rest_spheres, first_child, child_count, level have one entry per node;
///  - children of node i are first_child[i] .. first_child[i] + child_count[i] - 1,
///    all at level level[i] + 1; a leaf has child_count 0 (first_child -1);
///  - level_offset[l] is the index of the first node of level l, level_offset.back() == #nodes;
///  - assoc_offset has #nodes + 1 entries; node i's coarse nodes are
///    assoc_nodes[assoc_offset[i] .. assoc_offset[i+1]) with rest distances
///    assoc_rest_dist[...] (distance from the rest centre to the rest node position).
struct SphereTree {
  std::vector<Sphere> spheres;        ///< current spheres (updated each frame)
  std::vector<Sphere> rest_spheres;   ///< spheres in the undeformed configuration
  std::vector<int32_t> first_child;   ///< index of first child, -1 for leaves
  std::vector<int32_t> child_count;   ///< number of children (0 for leaves)
  std::vector<int32_t> level;         ///< depth of each node (root = 0)
  std::vector<int32_t> level_offset;  ///< first node of each level, plus #nodes at the end

  std::vector<int32_t> assoc_offset;    ///< CSR offsets into assoc_nodes (#nodes + 1), may be empty
  std::vector<int32_t> assoc_nodes;     ///< coarse node indices V_i of each sphere
  std::vector<double> assoc_rest_dist;  ///< rest distance from sphere centre to each assoc node

  int num_nodes() const { return static_cast<int>(spheres.size()); }
  int num_levels() const { return static_cast<int>(level_offset.size()) - 1; }
  bool is_leaf(int i) const { return child_count[i] == 0; }
};

/// True when the closed balls a and b intersect: |c_a - c_b| <= r_a + r_b.
inline bool overlap(const Sphere& a, const Sphere& b) {
  const double dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z, rr = a.r + b.r;
  return dx * dx + dy * dy + dz * dz <= rr * rr;
}

/// Checks every invariant listed at SphereTree (sizes, breadth-first order,
/// contiguous children one level deeper, level_offset, finite spheres with
/// r >= 0, CSR association data when present).
/// Throws icd::InputError naming the first offending node or field.
void validate(const SphereTree& tree);

/// Fills first_child, child_count, level and level_offset of `tree` from the
/// parent index of every node (parent[0] == -1; nodes listed breadth-first, so
/// parent[i] < i and parents do not decrease). `tree.spheres` must already hold
/// one sphere per node; rest_spheres is set to spheres if its size differs.
/// Throws icd::ParameterError when `parent` is not a breadth-first listing.
void build_topology(SphereTree& tree, const std::vector<int32_t>& parent);

/// Drops every level below `max_level` (>= 0): the nodes of level max_level
/// become leaves. Because the layout is breadth-first, the kept nodes are a
/// prefix of every array (association data included), so indices do not
/// change. A wrapped tree stays covering (each kept node covers its subtree's
/// surface patch). No-op when the tree is not deeper. Throws ParameterError
/// for a negative max_level.
void truncate_levels(SphereTree& tree, int max_level);

/// Parent index of every node (-1 for the root), the inverse of build_topology.
std::vector<int32_t> parents(const SphereTree& tree);

}  // namespace icd::collision
