#pragma once
/// Distance between two surfaces, for the preprocessing summary.
#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Approximate symmetric Hausdorff distance between two closed triangle
/// surfaces (model units): the largest distance from a sample of one surface
/// to the other surface, both ways. Samples are every vertex, edge midpoint
/// and face centroid (vertices used by no face are ignored), so the result is deterministic and a
/// lower bound of the exact distance (exact when the farthest point is a sample). Distances to a
/// surface are exact point-triangle distances (CGAL AABB tree).
/// Throws InputError for an empty mesh.
double approximate_hausdorff_distance(const SurfaceMesh& a, const SurfaceMesh& b);

/// The one-sided part: the largest distance from the samples of `from` (as
/// above) to the surface `to`. Throws InputError for an empty mesh.
double approximate_one_sided_distance(const SurfaceMesh& from, const SurfaceMesh& to);

}  // namespace icd::mesh
