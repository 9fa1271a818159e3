#pragma once
/// Ties every sphere of a tree to the coarse nodes V_i that steer its update
/// (paper 4.4): fills SphereTree::assoc_offset / assoc_nodes / assoc_rest_dist.
#include <vector>

#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::collision {

/// Options of associate_nearest_nodes().
struct NodeAssociationOptions {
  int k_nearest = 4;           ///< nodes nearest to the rest centre always taken (>= 1)
  bool include_inside = true;  ///< also take every candidate node inside the rest sphere
  int max_nodes = 64;          ///< cap on |V_i| (the nearest are kept), >= k_nearest
};

/// The paper's association: V_i = the k nearest candidate coarse nodes to the
/// rest centre of sphere i plus (optionally) every candidate inside the rest
/// sphere, capped at max_nodes (nearest first). A sphere enclosing no node
/// still gets its k nearest ones (the paper's heuristic for such spheres).
/// coarse_rest: #Vc x 3 rest positions of the coarse mesh (same units as the
/// tree). candidates: coarse node indices allowed (e.g. the coarse surface
/// nodes); empty = all nodes. Rest distances are measured from the rest centre.
/// Throws ParameterError for bad options or out-of-range candidates,
/// InputError when there is no candidate node.
void associate_nearest_nodes(SphereTree& tree, const Eigen::Ref<const MatX3d>& coarse_rest,
                             const NodeAssociationOptions& options = {},
                             const std::vector<int>& candidates = {});

/// The association that makes SphereUpdateMode::DisplacementBound conservative
/// (James & Pai's BD-tree argument): V_i = every coarse node that steers a
/// vertex of a dense triangle meeting rest sphere i, plus the k nearest nodes
/// of associate_nearest_nodes() (so the paper's update stays usable).
/// If every dense vertex's displacement is a convex combination of the
/// displacements of its steering nodes (e.g. linear interpolation in the
/// coarse tet containing it), every point of the surface patch under sphere i
/// moves by a convex combination of {u_j : j in V_i}.
/// dense_V #Vd x 3, dense_F #Fd x 3 (rest configuration); steer_offset (#Vd+1)
/// and steer_nodes: CSR list of the coarse nodes steering each dense vertex.
/// Throws InputError for inconsistent sizes or indices.
void associate_steering_nodes(SphereTree& tree, const Eigen::Ref<const MatX3d>& coarse_rest,
                              const Eigen::Ref<const MatX3d>& dense_V,
                              const Eigen::Ref<const MatX3i>& dense_F,
                              const std::vector<int32_t>& steer_offset,
                              const std::vector<int32_t>& steer_nodes, int k_nearest = 4);

}  // namespace icd::collision
