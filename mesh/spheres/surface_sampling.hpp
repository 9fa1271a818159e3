#pragma once
/// Deterministic surface sampling with a per-sample coverage margin.
#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Options of sample_surface().
struct SamplingOptions {
  /// Target distance between neighbouring samples (model units, > 0). Each
  /// triangle with longest edge L is split into n x n similar sub-triangles,
  /// n = ceil(L / spacing), so the number of samples per triangle grows with
  /// its area (about 2 area / (sqrt(3) spacing^2) for well-shaped triangles).
  double spacing = 1.0;
  /// Thin triangles (CAD fans, gear teeth) would get (L / spacing)^2 / 2
  /// needle-shaped lattice points whatever their area: a triangle is sampled
  /// by columns instead (points about 0.8 spacing apart on columns
  /// perpendicular to the longer leg of each half of it; samples about
  /// area / (0.8 spacing)^2 plus its edges' lengths / (0.8 spacing)) when
  /// the lattice would give it at least this many times as many points
  /// (>= 1). The default 8 leaves every triangle of the bunny and the dragon
  /// at the builder's coverage spacings on the lattice.
  double column_ratio = 8.0;
};

/// Surface samples: every mesh vertex, then the lattice points of each
/// triangle's n x n subdivision, or its column points (see
/// SamplingOptions::column_ratio) (edge points of neighbouring triangles may
/// appear twice; harmless).
///
/// Coverage guarantee: every surface point p lies within gap[i] of some
/// sample i. Hence a sphere set in which each sample i lies at distance
/// <= r - gap[i] from the centre of some sphere (c, r) covers the surface
/// completely (the gap is the coverage margin).
struct SurfaceSamples {
  MatX3d points;         ///< #S x 3 sample positions
  Eigen::VectorXd gap;   ///< #S coverage margin of each sample (model units)
  Eigen::VectorXd area;  ///< #S surface area represented by each sample (sums to the mesh area)
  Eigen::VectorXi face;  ///< #S triangle the sample lies on (for vertices: one incident face)
  int num_vertex_samples = 0;  ///< the first #V samples are the mesh vertices
};

/// Samples the triangle mesh (V #V x 3, F #F x 3). Deterministic. The gap of
/// a sample is the largest circumradius bound (longest edge / sqrt(3)) of the
/// lattice sub-triangles it is a corner of: any point of a triangle with
/// longest edge L is within L / sqrt(3) of one of its corners; on column
/// sub-triangles the exact bound (circumradius, or half the longest edge when
/// an angle is >= 90 deg), kept <= spacing / sqrt(3). Throws ParameterError
/// for a non-positive or non-finite spacing or a column_ratio below 1, and
/// InputError for bad indices or non-finite coordinates.
SurfaceSamples sample_surface(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F,
                              const SamplingOptions& options);

/// Total area of the triangle mesh (model units squared).
double surface_area(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F);

/// Axis-aligned bounding box longest side of V (model units).
double longest_bounding_box_side(const Eigen::Ref<const MatX3d>& V);

}  // namespace icd::mesh
