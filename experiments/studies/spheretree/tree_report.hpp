#pragma once
/// Printing the per-level metrics of sphere trees (sphere_tree_table,
/// evaluate_sph): one table format for every program of issue 5.
#include <ostream>
#include <string>
#include <vector>

#include <icd/collision/sph_io.hpp>
#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/types.hpp>
#include <icd/mesh/spheres/evaluation.hpp>

namespace icd::experiments {

/// Prints the table's explanation and column header.
void print_level_table_header();

/// Prints one row per level: `model` and `method` label the rows, `seconds`
/// is the build time shown in every row.
void print_level_table(const std::string& model, const std::string& method, double seconds,
                       const std::vector<mesh::LevelMetrics>& levels);

/// Worst and mean error of the spheres of one level.
struct LevelError {
  double worst = 0, mean = 0;
};

/// The worst and mean error of each level on 2562 directions (a 4 times
/// subdivided icosahedron; close to the continuous protrusion), in the units
/// `to_2000` turns model units into.
std::vector<LevelError> dense_errors(const SurfaceMesh& mesh, const collision::SphereTree& tree,
                                     double to_2000);

/// Prints, as comment lines, the worst and mean error of each level on 2562
/// directions (a 4 times subdivided icosahedron): close to the continuous
/// protrusion. `to_2000` turns model units into the table's.
void print_dense_errors(const std::string& label, const SurfaceMesh& mesh,
                        const collision::SphereTree& tree, double to_2000);

/// Factor from model units to the table's (longest bounding-box side 2000).
double to_normalized_units(const SurfaceMesh& mesh);

/// Centre of the axis-aligned bounding box of `mesh`'s vertices.
Eigen::Vector3d bounding_box_centre(const SurfaceMesh& mesh);

/// Reads a `.sph` tree into `mesh`'s coordinates: with `centred`, its
/// coordinates have the mesh's bounding-box centre at the origin (as
/// makeTreeMedial writes them) and are moved back. Throws what read_sph throws.
collision::SphereTree read_sph_for_mesh(const std::string& path, const SurfaceMesh& mesh,
                                        bool centred);

/// What grow_leaves_to_cover() did.
struct GrownLeaves {
  collision::SphereTree tree;       ///< the input tree with its leaves grown (model units)
  long long uncovered_samples = 0;  ///< coverage samples outside every leaf before
  int grown = 0;                    ///< leaves whose radius grew
  double largest_growth = 0;        ///< largest radius increase (normalized units)
};

/// The tree with its leaf level (the last) grown to cover the surface: each
/// coverage sample of evaluate_sphere_tree() (visit_coverage_samples at
/// `spacing`, normalized units; the mesh vertices are among them) outside
/// every leaf goes to the leaf whose surface is nearest to it (the least
/// growth), and each leaf's radius becomes the largest distance to a sample
/// it got (relative margin 1e-9), so that the evaluator finds the level
/// covering. The upper levels are unchanged. Brute force over the leaves.
GrownLeaves grow_leaves_to_cover(const SurfaceMesh& mesh, const collision::SphereTree& tree,
                                 double spacing);

/// What shrink_leaves_to_coverage_of() did.
struct ShrunkLeaves {
  collision::SphereTree tree;     ///< the input tree with its leaves shrunk (model units)
  long long dropped_samples = 0;  ///< coverage samples outside every leaf of `other`
  int emptied = 0;                ///< leaves left with no sample (radius 0)
};

/// The tree with its leaf level shrunk to cover only what `other`'s leaf
/// level covers (both in `mesh`'s coordinates): each coverage sample at
/// `spacing` (normalized units) inside some leaf of `other` goes to the leaf
/// of `tree` containing it most deeply (smallest |p - c| - r); samples of no
/// such leaf are dropped; each leaf's radius becomes the largest distance to
/// a sample it got (relative margin 1e-9; 0 when it got none). The surface
/// `other` leaves uncovered may then be uncovered by the result too (the
/// same coverage constraint). Throws ParameterError when a sample `other`
/// covers is outside every leaf of `tree`.
ShrunkLeaves shrink_leaves_to_coverage_of(const SurfaceMesh& mesh,
                                          const collision::SphereTree& tree,
                                          const collision::SphereTree& other, double spacing);

/// Writes one CSV row per leaf (normalized units, origin at the mesh's
/// bounding-box centre): leaf, x, y, z, r, depth (signed distance of the
/// centre to the hole-closed surface, > 0 inside), sx, sy, sz (the surface
/// point nearest to the centre), e162 (error on our 162 probes), e2562 (on
/// 2562 directions).
void write_leaf_table(std::ostream& out, const SurfaceMesh& mesh,
                      const collision::SphereTree& tree);

/// Writes one CSV row per coverage sample at `spacing` (normalized units,
/// visit_coverage_samples; origin at the bounding-box centre): x, y, z, nx,
/// ny, nz (the triangle's outward normal), w (area weight), leaves (number of
/// leaves containing the point), reach (how far the leaves containing it
/// reach from it along the normal; 0 when none does). Two trees of one mesh
/// give rows in the same order.
void write_sample_table(std::ostream& out, const SurfaceMesh& mesh,
                        const collision::SphereTree& tree, double spacing);

}  // namespace icd::experiments
