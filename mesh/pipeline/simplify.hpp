#pragma once
/// Stage 2 of the preprocessing pipeline (issue 4, paper section 5): quadric
/// error metric simplification (Garland-Heckbert, CGAL Surface_mesh_simplification).
#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Options of simplify_surface(). The target is target_faces when > 0,
/// otherwise target_ratio * input faces.
struct SimplifyOptions {
  int target_faces = 4000;    ///< faces of the output (approximately: an edge collapse removes 2)
  double target_ratio = 0.0;  ///< in (0, 1]; used only when target_faces == 0
  /// Reject collapses that flip a face normal (CGAL Bounded_normal_change_filter):
  /// avoids folds that would make the surface self-intersect.
  bool bounded_normal_change = true;
  /// Check the result for self-intersections; retry with twice the faces
  /// (until the input's count, which is kept) while it intersects itself.
  bool check_self_intersections = true;
};

/// What simplify_surface() did.
struct SimplifyReport {
  int input_faces = 0, output_faces = 0;
  int collapsed_edges = 0;
  int self_intersection_retries = 0;  ///< results that intersected themselves and were redone
};

/// Result of simplify_surface().
struct SimplifyResult {
  SurfaceMesh mesh;
  SimplifyReport report;
};

/// Simplifies a closed, manifold, oriented triangle surface (e.g. the output
/// of repair_surface()) by edge collapses with Garland-Heckbert plane
/// quadrics until it has at most the target number of faces (or no collapse
/// is allowed). An input already below the target is returned unchanged.
/// The output keeps orientation and closedness; it is not re-checked for
/// self-intersections (tetrahedralize_surface() works on it regardless).
/// Throws ParameterError for a bad target, InputError when the input is not a
/// manifold oriented triangle mesh.
SimplifyResult simplify_surface(const SurfaceMesh& input, const SimplifyOptions& options = {});

}  // namespace icd::mesh
