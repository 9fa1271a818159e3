#pragma once
/// How well a (deformed) sphere tree covers a (deformed) dense surface.
#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::collision {

/// Result of measure_coverage().
struct CoverageReport {
  int num_points = 0;             ///< points tested
  int num_uncovered = 0;          ///< points outside every sphere of the cut
  double uncovered_fraction = 0;  ///< num_uncovered / num_points (0 when no point)
  double max_gap = 0;  ///< largest distance from an uncovered point to the nearest sphere surface
};

/// Fraction of the points P (#P x 3, e.g. the deformed dense vertices) that
/// lie outside every sphere of a cut of the tree: the spheres on `level` plus
/// the leaves above it, or, for level = -1, all leaves. Uses a uniform grid
/// over the spheres' bounding boxes (no dependence on the tree's quality).
/// Throws ParameterError for a level outside [-1, num_levels).
CoverageReport measure_coverage(const SphereTree& tree, const Eigen::Ref<const MatX3d>& P,
                                int level = -1);

}  // namespace icd::collision
