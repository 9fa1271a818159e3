#pragma once
/// Statistics of a triangle surface mesh, for inspecting raw assets
/// (icd-meshinfo) and checking preprocessing results.
#include <cstdint>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>

namespace icd {

/// Counts and measures of a surface mesh. Edges are undirected vertex pairs
/// {i, j} used by at least one face.
struct SurfaceStats {
  int64_t vertices = 0;                                ///< #V (referenced or not)
  int64_t faces = 0;                                   ///< #F
  int64_t edges = 0;                                   ///< distinct undirected edges
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();  ///< (0,0,0) when #V = 0
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();
  double area = 0.0;  ///< sum of triangle areas (units^2)
  /// Signed enclosed volume sum_f v0 . (v1 x v2) / 6 (units^3): the true
  /// volume for a closed, outward-oriented surface; meaningless otherwise.
  double volume = 0.0;
  int64_t boundary_edges = 0;     ///< edges with exactly one incident face
  int64_t nonmanifold_edges = 0;  ///< edges with more than two incident faces
  /// Edges with two incident faces that traverse them in the same direction
  /// (the orientation flips across the edge).
  int64_t inconsistent_edges = 0;
  /// Vertices at exactly the position of a lower-index vertex (a welded mesh has 0).
  int64_t duplicate_vertices = 0;
  int64_t unreferenced_vertices = 0;  ///< vertices used by no face
  /// Faces with a repeated vertex index, or with |(b-a) x (c-a)| <= 1e-12 *
  /// (longest edge)^2 (zero area up to rounding).
  int64_t degenerate_faces = 0;
  int64_t components = 0;            ///< connected components of the faces (by shared vertices)
  int64_t euler_characteristic = 0;  ///< #V - #E + #F
};

/// Computes SurfaceStats in O(#F log #F). Throws ParameterError if V has a
/// non-finite coordinate or F an index outside [0, #V).
SurfaceStats compute_surface_stats(const SurfaceMesh& mesh);

}  // namespace icd
