#pragma once
/// Per-level quality of a sphere tree against its surface (issue 5 metrics).
#include <functional>
#include <vector>

#include <Eigen/Core>

#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Options of evaluate_sphere_tree().
struct EvaluationOptions {
  /// The model (and tree) are scaled so that the longest bounding-box side
  /// is this long; every length reported is in these units.
  double normalized_size = 2000.0;
  /// Spacing of the dense coverage sampling, in normalized units (> 0): each
  /// triangle is split into n x n sub-triangles (n = ceil(longest edge /
  /// spacing)) whose corners are tested, weighted by a third of each
  /// sub-triangle's area. Make it much finer than the build's samples.
  double coverage_spacing = 1.0;
  /// Points per sphere of the shell-volume estimate (LevelMetrics::shell_thickness;
  /// drawn with a seed from the sphere's centre and radius, so the estimate does
  /// not depend on the order of the spheres;
  /// 0 skips it; >= 0).
  int shell_samples = 256;
  /// Orientation of the probe directions (orthogonal): the probes of a
  /// sphere are c + r * probe_frame * d, d from probe_directions(). The
  /// identity is our icosahedron; toolkit_probe_frame() turns it into the
  /// reference toolkit's.
  Eigen::Matrix3d probe_frame = Eigen::Matrix3d::Identity();
  /// Random orientations of the 42 probes per sphere behind
  /// LevelMetrics::worst_error_42_rotated / mean_error_42_rotated (>= 0; 0
  /// skips them).
  int probe_rotations = 16;
};

/// Metrics of one level of the tree (normalized units).
struct LevelMetrics {
  int level = 0;
  int num_spheres = 0;
  /// Error of a sphere with P probes: the largest distance to the surface of
  /// the probes c + r d (d: the P vertices of a subdivided icosahedron) that
  /// lie outside the closed mesh (0 when none does). Worst and mean over the level.
  double worst_error_42 = 0, mean_error_42 = 0;
  double worst_error_162 = 0, mean_error_162 = 0;
  /// The 42-probe error of each sphere averaged over
  /// EvaluationOptions::probe_rotations uniformly random orientations of the
  /// probes (one set per sphere, seeded by its centre and radius, so independent of the sphere
  /// order); worst and mean over the level. A tree fitted against one fixed set of probe directions
  /// (as the reference toolkit fits its spheres against its own 42 points) looks better on those
  /// directions than on any other 42; these numbers belong to no frame and are the 42-probe figures
  /// to compare trees by.
  double worst_error_42_rotated = 0, mean_error_42_rotated = 0;
  double uncovered_area_fraction = 0;   ///< area of dense samples outside every sphere / total area
  long long num_dense_samples = 0;      ///< dense samples tested
  long long num_uncovered_samples = 0;  ///< dense samples outside every sphere of the level
  double max_uncovered_gap =
      0;  ///< largest distance from an uncovered sample to the nearest sphere
  int num_uncovered_vertices = 0;  ///< mesh vertices outside every sphere of the level
  /// Spheres that cover no dense sample and no vertex alone: every point of
  /// the surface they cover (as sampled) another sphere of the level covers
  /// too, so removing one of them uncovers nothing. Such a sphere (say, one
  /// tucked inside the object, touching the surface at a point) has a small
  /// error and pulls the level's mean down without covering anything; the
  /// means over the other spheres say what the covering spheres achieve.
  int num_redundant_spheres = 0;
  double mean_error_42_covering = 0;   ///< mean 42-probe error of the other spheres
  double mean_error_162_covering = 0;  ///< mean 162-probe error of the other spheres
  /// Volume of the level's union of spheres outside the object divided by
  /// the surface area: the mean thickness of the shell the level adds around
  /// the object (normalized units). Unlike the mean error it does not depend
  /// on how many spheres share the work, and a sphere inside the object adds
  /// nothing. Estimated by sampling each sphere's part beyond its centre's
  /// depth (EvaluationOptions::shell_samples points, fixed seed), each point
  /// weighted by one over the number of spheres that contain it.
  double shell_thickness = 0;
  /// Over the surface (the dense samples, weighted by area): how far the
  /// level's spheres that contain a point reach from it along the outward
  /// normal of its triangle (0 for an uncovered point); the area-weighted
  /// median and 90th percentile (normalized units, to 0.25). What a contact
  /// at a typical point sees: the level reports it that far before the
  /// surfaces touch.
  double thickness_median = 0, thickness_p90 = 0;
  /// How far the level's spheres stick out of their parents (max over nodes
  /// of |c - c_parent| + r - r_parent, >= 0; 0 for the root).
  double max_child_protrusion = 0;
};

/// Evaluates every level of `tree` (model units, built for `mesh`: V #V x 3,
/// F #F x 3, outward-oriented) after scaling both so the longest side of the
/// mesh's bounding box is options.normalized_size. Holes are closed (see
/// close_holes) before any inside test; coverage is measured on the input
/// surface. Throws ParameterError for bad options or an invalid tree (see
/// collision::validate), InputError for an empty or degenerate mesh.
std::vector<LevelMetrics> evaluate_sphere_tree(const SurfaceMesh& mesh,
                                               const collision::SphereTree& tree,
                                               const EvaluationOptions& options = {});

/// Called with a coverage sample, its triangle's unit outward normal and its
/// area weight.
using CoverageSampleVisitor =
    std::function<void(const Eigen::Vector3d& p, const Eigen::Vector3d& normal, double weight)>;

/// The dense coverage samples of evaluate_sphere_tree() (there in normalized
/// units): each triangle of `mesh` (V #V x 3, F #F x 3) is split into n x n
/// sub-triangles (n = ceil(longest edge / spacing), spacing in the mesh's
/// units, > 0) whose corners are visited, each weighted by a third of the
/// area of the sub-triangles it is a corner of (a point shared by triangles
/// is visited once per triangle). Returns the surface area (the sum of the
/// weights). Throws ParameterError for spacing <= 0.
double visit_coverage_samples(const SurfaceMesh& mesh, double spacing,
                              const CoverageSampleVisitor& visit);

/// The probe directions: vertices of the icosahedron subdivided `subdivisions`
/// times (12, 42, 162, ... unit vectors).
MatX3d probe_directions(int subdivisions);

/// The frame in which probe_directions(s) are the sphere points of the
/// reference Sphere Tree Construction Toolkit (Bradshaw 2003; its
/// icosahedron has vertices (+-X, 0, +-Z), (0, +-Z, +-X), (+-Z, +-X, 0) with
/// Z > X, subdivided the same way; its makeTreeMedial fits each sphere
/// against 42 of them with `-testerLevels 2`): ours with x and z swapped.
Eigen::Matrix3d toolkit_probe_frame();

}  // namespace icd::mesh
