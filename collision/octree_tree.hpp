#pragma once
/// The Hubbard-style octree sphere tree, the simple baseline of issue 5: the
/// bounding cube of the surface is subdivided recursively (branching 8); every
/// occupied cell gets one sphere enclosing the part of the surface inside it.
#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::collision {

/// Options of build_octree_tree().
struct OctreeTreeOptions {
  int levels = 3;                 ///< tree depth counting the root (>= 1); leaves on level levels-1
  double margin = 0.0;            ///< absolute amount added to every radius (model units, >= 0)
  double relative_margin = 1e-9;  ///< added radius relative to the root cube side, absorbs rounding
};

/// Builds an octree sphere tree for the surface (V #V x 3, F #F x 3).
///
/// Each triangle is clipped exactly (Sutherland-Hodgman against the closed
/// cell box) to every cell it meets; the sphere of a cell is centred at the
/// bounding-box centre of the clipped polygons and reaches their farthest
/// vertex. Because a ball is convex and contains the clipped polygon's vertices,
/// it contains the whole surface part in the cell: every level covers the
/// whole surface and every node covers its subtree's surface patch, with no
/// sampling gaps (so no sampling margin is needed). Deterministic.
/// Children are the occupied octants in the order (x fastest, then y, z).
/// Leaves are on the last level (or earlier where clipping leaves nothing).
/// rest_spheres == spheres; no coarse-node association is set.
/// Throws ParameterError for levels < 1 or a negative margin, InputError for
/// an empty mesh, out-of-range indices or non-finite vertices.
SphereTree build_octree_tree(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F,
                             const OctreeTreeOptions& options = {});

}  // namespace icd::collision
