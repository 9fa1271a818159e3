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
// --cover-leaves FILE: the leaf level is first grown until it covers every
// coverage sample (grow_leaves_to_cover: each uncovered sample goes to the
// nearest leaf), written to FILE (mesh coordinates), and that tree is
// evaluated. --cover-only-as OTHER.sph --shrunk FILE: the leaves are shrunk
// to cover only what OTHER's leaves cover (shrink_leaves_to_coverage_of),
// written to FILE and evaluated. --leaf-table / --sample-table FILE:
// per-leaf and per-sample CSV of the leaf level as evaluated
// (tree_report.hpp) for region studies.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>

#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/studies/spheretree/tree_report.hpp"
#include <icd/collision/sph_io.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/spheres/evaluation.hpp>

namespace {

using icd::experiments::Cli;

/// Reads an option's value into `target`: a finite number > 0, else the
/// command-line error (status 2).
std::function<void(const std::string&)> positive(double& target) {
  return [&target](const std::string& v) {
    const double x = Cli::parse_real(v);
    if (!(x > 0)) throw std::invalid_argument("must be > 0, got '" + v + "'");
    target = x;
  };
}

int run(int argc, char** argv) {
  std::filesystem::path mesh_path, tree_path;
  std::string name = "tree";
  icd::mesh::EvaluationOptions evaluation;
  bool dense = true, centred = false;
  std::filesystem::path cover_path, leaf_table, sample_table, shrink_path, other_path;
  bool other_centred = false;
  double sample_spacing = 4.0;
  Cli cli(
      "evaluate_sph", "  Evaluates a .sph sphere tree against its surface mesh (issue 5 metrics).");
  cli.argument("MESH", mesh_path, "surface mesh (OFF, OBJ, PLY, STL) the tree was built for", true)
      .argument("TREE", tree_path, ".sph sphere tree in the mesh's coordinates", true);
  cli.text("--name", name, "NAME", "label of the rows")
      .custom("--coverage-spacing", "UNITS", "dense coverage spacing (normalized units, > 0)",
              positive(evaluation.coverage_spacing))
      .integer("--shell-samples", evaluation.shell_samples, "N", "shell points per sphere", 0)
      .integer("--rotations", evaluation.probe_rotations, "N",
               "random orientations of the 42 probes per sphere", 0)
      .boolean("--dense", dense, "also the errors on 2562 directions")
      .boolean("--centred", centred,
               "the tree is centred on the mesh's bounding-box centre (makeTreeMedial's output)")
      .path("--cover-leaves", cover_path, "FILE",
            "grow the leaves until they cover the surface, write that tree to FILE, evaluate it")
      .path("--leaf-table", leaf_table, "FILE", "per-leaf CSV (centre, radius, depth, errors)")
      .path("--sample-table", sample_table, "FILE",
            "per-coverage-sample CSV (leaves containing it, reach along the normal)")
      .custom("--sample-spacing", "UNITS", "spacing of --sample-table's samples (> 0)",
              positive(sample_spacing))
      .path("--cover-only-as", other_path, "OTHER.sph",
            "shrink the leaves to cover only what OTHER's leaves cover (with --shrunk)")
      .boolean("--other-centred", other_centred, "OTHER is centred (as --centred)")
      .path("--shrunk", shrink_path, "FILE",
            "write the tree shrunk by --cover-only-as to FILE and evaluate it");
  if (const auto status = cli.parse(argc, argv)) return *status;
  if (other_path.empty() != shrink_path.empty())
    return Cli::fail("evaluate_sph", "--cover-only-as and --shrunk go together");

  const icd::SurfaceMesh mesh = icd::read_surface_mesh(mesh_path);
  icd::collision::SphereTree tree =
      icd::experiments::read_sph_for_mesh(tree_path.string(), mesh, centred);
  if (!cover_path.empty()) {
    icd::experiments::GrownLeaves grown =
        icd::experiments::grow_leaves_to_cover(mesh, tree, evaluation.coverage_spacing);
    std::printf(
        "# --cover-leaves: %lld coverage samples were outside every leaf; %d leaves grown, by "
        "at most %.3f units; written to %s\n",
        grown.uncovered_samples, grown.grown, grown.largest_growth, cover_path.string().c_str());
    icd::collision::write_sph(cover_path.string(), grown.tree);
    tree = std::move(grown.tree);
  }
  if (!other_path.empty()) {
    const icd::collision::SphereTree other =
        icd::experiments::read_sph_for_mesh(other_path.string(), mesh, other_centred);
    icd::experiments::ShrunkLeaves shrunk = icd::experiments::shrink_leaves_to_coverage_of(
        mesh, tree, other, evaluation.coverage_spacing);
    std::printf(
        "# --cover-only-as: %lld coverage samples outside %s's leaves need no cover; %d leaves "
        "cover nothing else (radius 0); written to %s\n",
        shrunk.dropped_samples, other_path.string().c_str(), shrunk.emptied,
        shrink_path.string().c_str());
    icd::collision::write_sph(shrink_path.string(), shrunk.tree);
    tree = std::move(shrunk.tree);
  }
  auto write_table = [&](const std::filesystem::path& path, auto&& write) {
    if (path.empty()) return;
    std::ofstream out(path);
    write(out);
    if (!out.flush()) throw icd::InputError(path.string() + ": cannot be written");
  };
  write_table(leaf_table,
              [&](std::ostream& out) { icd::experiments::write_leaf_table(out, mesh, tree); });
  write_table(sample_table, [&](std::ostream& out) {
    icd::experiments::write_sample_table(out, mesh, tree, sample_spacing);
  });
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
  return icd::experiments::guarded_main("evaluate_sph", run, argc, argv);
}
