// evaluate_sph MESH TREE.sph [--name NAME] [--coverage-spacing UNITS] [--shell-samples N]
//              [--rotations N] [--dense 0|1] [--centred 0|1]
//
// Evaluates any sphere tree in the `.sph` format (ours, or one written by
// another tool such as the reference Sphere Tree Construction Toolkit's
// makeTreeMedial, whose trailing options and evaluation are ignored) against
// the surface mesh it was built for, with the metrics of sphere_tree_table
// (normalized units: longest bounding-box side 2000). The 42- and 162-probe
// errors are given twice: probed in our frame (method "ours") and in the
// toolkit's (method "toolkit": the 42 points the toolkit fits its spheres
// against with -testerLevels 2); the rotated 42-probe errors, the shell and
// the 2562-direction errors belong to no frame (the same on both rows).
// --centred 1: the tree's coordinates have the mesh's bounding-box centre at
// the origin, as makeTreeMedial writes them (it centres and scales the model,
// and undoes only the scale when saving).
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>

#include "experiments/common/cli.hpp"
#include "experiments/studies/spheretree/tree_report.hpp"
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/spheres/evaluation.hpp>

namespace {

int run(int argc, char** argv) {
  std::filesystem::path mesh_path, tree_path;
  std::string name = "tree";
  icd::mesh::EvaluationOptions evaluation;
  bool dense = true, centred = false;
  icd::experiments::Cli cli(
      "evaluate_sph", "  Evaluates a .sph sphere tree against its surface mesh (issue 5 metrics).");
  cli.argument("MESH", mesh_path, "surface mesh (OFF, OBJ, PLY, STL) the tree was built for", true)
      .argument("TREE", tree_path, ".sph sphere tree in the mesh's coordinates", true);
  cli.text("--name", name, "NAME", "label of the rows")
      .real("--coverage-spacing", evaluation.coverage_spacing, "UNITS",
            "dense coverage spacing (normalized units)")
      .integer("--shell-samples", evaluation.shell_samples, "N", "shell points per sphere", 0)
      .integer("--rotations", evaluation.probe_rotations, "N",
               "random orientations of the 42 probes per sphere", 0)
      .boolean("--dense", dense, "also the errors on 2562 directions")
      .boolean("--centred", centred,
               "the tree is centred on the mesh's bounding-box centre (makeTreeMedial's output)");
  if (const auto status = cli.parse(argc, argv)) return *status;

  const icd::SurfaceMesh mesh = icd::read_surface_mesh(mesh_path);
  const icd::collision::SphereTree tree =
      icd::experiments::read_sph_for_mesh(tree_path.string(), mesh, centred);
  std::printf(
      "# %s: %s (%d nodes, %d levels) on %s (%lld vertices, %lld triangles); %d probe "
      "orientations per sphere, coverage spacing %g, %d shell points per sphere\n",
      name.c_str(), tree_path.string().c_str(), tree.num_nodes(), tree.num_levels(),
      mesh_path.string().c_str(), static_cast<long long>(mesh.V.rows()),
      static_cast<long long>(mesh.F.rows()), evaluation.probe_rotations,
      evaluation.coverage_spacing, evaluation.shell_samples);
  icd::experiments::print_level_table_header();
  icd::experiments::print_level_table(name, "ours", 0.0,
                                      icd::mesh::evaluate_sphere_tree(mesh, tree, evaluation));
  icd::mesh::EvaluationOptions toolkit = evaluation;
  toolkit.probe_frame = icd::mesh::toolkit_probe_frame();
  icd::experiments::print_level_table(name, "toolkit", 0.0,
                                      icd::mesh::evaluate_sphere_tree(mesh, tree, toolkit));
  if (dense)
    icd::experiments::print_dense_errors(name, mesh, tree,
                                         icd::experiments::to_normalized_units(mesh));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "evaluate_sph: " << e.what() << "\n";
    return 1;
  }
}
