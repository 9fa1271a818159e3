#pragma once
/// Adaptive medial-axis approximation (Bradshaw & O'Sullivan 2004, sec. 3):
/// the Voronoi vertices of surface samples that lie inside the object, with
/// their distance to the surface, refined where they are poor.
#include <vector>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

namespace icd::mesh {

/// Options of approximate_medial_axis().
struct MedialAxisOptions {
  /// Refinement rounds: in each, every inner Voronoi vertex whose Delaunay
  /// circumsphere sticks out of the object by more than `error_tolerance`
  /// adds the surface point nearest its centre to the triangulation (>= 0).
  int refinement_iterations = 2;
  /// Error (model units) above which a medial sphere is refined (> 0).
  double error_tolerance = 1.0;
  /// At most this many points are inserted per refinement round (>= 0).
  int max_insertions_per_iteration = 20000;
};

/// Medial spheres: centre and *inscribed* radius (the exact distance from the
/// centre to the surface, so every sphere lies inside the object), and for
/// the Voronoi ones the Delaunay circumradius (distance to the nearest sample).
struct MedialSpheres {
  MatX3d centers;               ///< #M x 3 centres (inside the closed mesh)
  Eigen::VectorXd radii;        ///< #M inscribed radii (distance to the surface, >= 0)
  Eigen::VectorXd circumradii;  ///< #M distance to the nearest sample (>= radii up to sampling)
  int num_voronoi = 0;   ///< the first num_voronoi are Voronoi vertices, the rest cover spheres
  int num_inserted = 0;  ///< points added by the adaptive refinement
};

/// Builds the medial-sphere set of the closed mesh behind `oracle` from the
/// surface samples `samples` (their points and faces are used): Delaunay
/// triangulation (CGAL Delaunay_triangulation_3), circumcentres inside the
/// mesh (Side_of_triangle_mesh), adaptive refinement, then one cover sphere
/// (centre pushed inside along the face normal) for each sample that no
/// inner Delaunay cell touches. Deterministic. Throws ParameterError for bad
/// options and InputError when fewer than 4 non-coplanar samples are given.
MedialSpheres approximate_medial_axis(const MeshOracle& oracle, const SurfaceSamples& samples,
                                      const MedialAxisOptions& options);

/// The same on oracles.size() worker threads, one oracle of the same mesh
/// per worker (MeshOracle's inside test is not safe for concurrent use); the
/// inside tests and distances of the Delaunay cells and the refinement's
/// nearest surface points are computed in parallel, the triangulation is
/// built serially. The result does not depend on the number of workers.
/// Throws ParameterError when `oracles` is empty or holds a null pointer.
MedialSpheres approximate_medial_axis(const std::vector<const MeshOracle*>& oracles,
                                      const SurfaceSamples& samples,
                                      const MedialAxisOptions& options);

}  // namespace icd::mesh
