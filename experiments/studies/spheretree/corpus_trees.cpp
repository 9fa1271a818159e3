// corpus_trees BUNDLE [--sph-dir DIR] [--coverage-spacing UNITS] [--shell-samples N]
//              [--rotations N]
//
// Evaluates the sphere tree of an asset bundle (a folder written by
// icd-preprocess: the tree the runtime loads) against the bundle's dense
// surface with the metrics of evaluate_sph (normalized units: longest
// bounding-box side 2000) and prints, under a header line, one tab-separated
// row for its leaf level (the last level): leaves, worst/mean error on 42
// probes, worst/mean on 162, mean/worst on 2562 directions, the uncovered share
// of the dense samples and the vertices outside every leaf. A bad bundle
// (InputError naming its file) gives exit 1 and no row.
// experiments/studies/spheretree/corpus_trees.py runs it on each corpus bundle
// and writes the corpus table.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/studies/spheretree/tree_report.hpp"
#include <icd/collision/sph_io.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/cpu_clock.hpp>
#include <icd/mesh/spheres/evaluation.hpp>

namespace {

int run(int argc, char** argv) {
  std::filesystem::path bundle, sph_dir;
  icd::mesh::EvaluationOptions evaluation;
  evaluation.shell_samples = 0;
  evaluation.probe_rotations = 0;
  icd::experiments::Cli cli(
      "corpus_trees",
      "  Evaluates the leaf level of an asset bundle's sphere tree against the bundle's\n"
      "  dense surface (units: longest bounding-box side 2000) and prints one tab-separated\n"
      "  row under a header. Shell and rotated-probe figures are off unless asked for.");
  cli.argument("BUNDLE", bundle, "asset bundle folder (icd-preprocess -o FOLDER)", true);
  cli.path("--sph-dir", sph_dir, "DIR", "also write the bundle's tree as DIR/<folder name>.sph")
      .real("--coverage-spacing", evaluation.coverage_spacing, "UNITS",
            "dense coverage spacing (normalized units)")
      .integer("--shell-samples", evaluation.shell_samples, "N",
               "shell points per sphere (0: no shell figure)", 0)
      .integer("--rotations", evaluation.probe_rotations, "N",
               "random orientations of the 42 probes per sphere (0: none)", 0);
  if (const auto status = cli.parse(argc, argv)) return *status;

  const icd::coupling::AssetBundle b = icd::coupling::read_asset_bundle(bundle);
  if (b.spheres.num_nodes() == 0)
    throw icd::InputError(bundle.string() + ": the bundle has no sphere tree");
  const auto start = icd::mesh::CpuClock::now();
  const std::filesystem::path folder = bundle.filename().empty() ? bundle.parent_path() : bundle;
  const std::string name = folder.filename().string();
  icd::collision::SphereTree tree = b.spheres;
  tree.spheres = tree.rest_spheres;  // the rest configuration (as loaded, they are equal)
  // Only the leaf level is reported: evaluate the root with the leaves as its
  // children (a level's figures depend on its own spheres only), which halves
  // the coverage sampling of a 4-level tree.
  const int num_levels = tree.num_levels();
  const int leaf_begin = tree.level_offset[static_cast<size_t>(num_levels - 1)];
  icd::collision::SphereTree flat;
  flat.spheres.push_back(tree.spheres[0]);
  std::vector<int32_t> parent{-1};
  for (int i = leaf_begin; i < tree.num_nodes() && num_levels > 1; ++i) {
    flat.spheres.push_back(tree.spheres[static_cast<size_t>(i)]);
    parent.push_back(0);
  }
  icd::collision::build_topology(flat, parent);
  const auto levels = icd::mesh::evaluate_sphere_tree(b.dense, flat, evaluation);
  const icd::mesh::LevelMetrics& m = levels.back();
  const icd::experiments::LevelError dense =
      icd::experiments::dense_errors(b.dense, flat, icd::experiments::to_normalized_units(b.dense))
          .back();
  const double eval_cpu_s =
      std::chrono::duration<double>(icd::mesh::CpuClock::now() - start).count();
  if (!sph_dir.empty()) {
    std::filesystem::create_directories(sph_dir);
    icd::collision::write_sph((sph_dir / (name + ".sph")).string(), tree);
  }
  std::printf(
      "bundle\ttriangles\tlevels\tleaves\tworst42\tmean42\tworst162\tmean162\tmean2562\tworst2562"
      "\tuncovered_pct\tuncovered_vertices\tredundant\tshell\tmean42r\teval_cpu_s\n");
  std::printf("%s\t%lld\t%d\t%d\t%.1f\t%.2f\t%.1f\t%.2f\t%.2f\t%.1f\t%.5f\t%d\t%d\t%.2f\t%.2f\t%.1f\n",
              name.c_str(), static_cast<long long>(b.dense.F.rows()),
              num_levels, m.num_spheres, m.worst_error_42, m.mean_error_42,
              m.worst_error_162, m.mean_error_162, dense.mean, dense.worst,
              100.0 * m.uncovered_area_fraction, m.num_uncovered_vertices,
              m.num_redundant_spheres, m.shell_thickness, m.mean_error_42_rotated, eval_cpu_s);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("corpus_trees", run, argc, argv);
}
