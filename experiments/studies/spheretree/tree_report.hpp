#pragma once
/// Printing the per-level metrics of sphere trees (sphere_tree_table,
/// evaluate_sph): one table format for every program of issue 5.
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

}  // namespace icd::experiments
