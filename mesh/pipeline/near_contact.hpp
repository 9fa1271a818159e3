#pragma once
/// Distinct parts of a surface in near contact (issue 30, items 2 and 7): two
/// connected components closer to each other than the mesher's surface
/// tolerance make Mesh_3 refine between them until it stops at its vertex cap
/// (the corpus' bones: 26 bones 0.1 % of the diagonal apart). preprocess()
/// measures the gap before meshing and meshes the alpha wrap at once.
#include <array>
#include <cmath>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// The closest approach of two distinct connected components of a surface
/// (trivially copyable: it crosses the stage's process boundary).
struct ComponentGap {
  int components = 0;  ///< connected components (faces sharing a vertex)
  /// Smallest distance from a vertex of one component to a triangle of
  /// another (an upper bound of the true gap, exact where a vertex is the
  /// closest feature); infinity when there is one component.
  double distance = INFINITY;
  int first = -1, second = -1;    ///< the two components (numbered by their first face)
  std::array<double, 3> where{};  ///< midpoint of the closest pair
  /// Vertices within `within` of another component's triangles (a contact
  /// at one point, as the two fans of a split non-manifold vertex, gives 2).
  int close_vertices = 0;
};

/// Measures the closest approach of distinct components of `surface`
/// (triangles, indices in range) and counts the vertices within `within` of
/// another component. Components whose bounding boxes lie farther apart than
/// `within` are not compared (the distance is then infinity for them; pass
/// INFINITY to compare all). Deterministic.
ComponentGap closest_component_gap(const SurfaceMesh& surface, double within = INFINITY);

}  // namespace icd::mesh
