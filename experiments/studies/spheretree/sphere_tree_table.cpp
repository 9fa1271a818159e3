// sphere_tree_table RESULTS_DIR [--models bunny,dragon] [--mesh PATH]... [--time-limit S]
//                   [--medial-spacing REL]
//                   [--cover-spacing REL] [--joint 0|1] [--regroup 0|1] [--lloyd N] [--octree 0|1]
//                   [--worst-share F] [--leaf-worst-target REL] [--leaf-worst-factor F]
//                   [--coverage-spacing UNITS] [--shell-samples N]  (evaluation)
//                   [--diagnose N]   (print the N leaves with the largest 162-probe error)
//                   [--exchange-rounds N] [--relieve-moves N]
//                   [--polish 0|1] [--polish-rounds N] [--polish-evals N]
//                   [--polish-search N] [--polish-check N]
//                   [--sum-passes N] [--sum-cap F] [--sum-share F]   (lower_error_sum)
//                   [--fit-probes 0|1]  (also: the leaves re-polished against the 42
//                                        evaluation directions, to show what that fit does)
//                   [--split-worst 0|1] [--split-tries N] [--split-relief F] [--split-mean-rise F]
//                                 (SphereTreeOptions::WorstSplit)
//                   [--caps 1,8,64,N[,M]]  (spheres allowed per level; depth = count - 1)
//                   [--branching B]  (children per node at most; default 8)
//                   [--build-branching B]  (SphereTreeOptions::Allocation::build_branching)
//                   [--threads N]  (worker threads of the build; 0 = all cores, the default)
//                   [--fit light|full|shell]  (icd-preprocess's --sphere-fit presets; give it
//                                 first: it resets the optimisation options before it)
//                   [--refinement N]  (adaptive medial-axis rounds)
//                   [--canonical 0|1]  (build on the mesh in canonical order, as icd-preprocess)
//                   [--flat N]  (diagnostic: one level of at most N spheres under the root,
//                                every other step as usual: the cost of the nested partition)
//                   [--perturb E]  (build for the mesh scaled by 1 + E, evaluate on the
//                                   mesh: E ~ 1e-12 shows the build's sensitivity to rounding)
//
// Builds the wrapped sphere tree (adaptive medial axis, branching 8, depth 3,
// at most 1/8/64/445 spheres per level as the reference toolkit's dragon tree)
// and the Hubbard octree baseline (4 levels) for the bunny and the dragon,
// prints per-level metrics (normalized units: longest bounding-box side 2000),
// and writes each tree as .sph and one VTU sphere set per level into RESULTS_DIR.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <icd/collision/octree_tree.hpp>
#include <icd/collision/sph_io.hpp>
#include <icd/collision/sphere_tree.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/studies/spheretree/tree_report.hpp"
#include <icd/config.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/vtk_writer.hpp>
#include <icd/mesh/pipeline/canonical.hpp>
#include <icd/mesh/pipeline/preprocess.hpp>
#include <icd/mesh/spheres/builder.hpp>
#include <icd/mesh/spheres/evaluation.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/parallel.hpp>
#include <icd/mesh/spheres/protrusion.hpp>

namespace {

namespace fs = std::filesystem;

struct Model {
  std::string name;
  std::string file;
};

void write_tree(const fs::path& dir, const std::string& stem,
                const icd::collision::SphereTree& tree) {
  int branch = 8;  // the .sph header's branching: 8, or more for a --flat tree
  for (int count : tree.child_count) branch = std::max(branch, count);
  icd::collision::write_sph((dir / (stem + ".sph")).string(), tree, branch);
  for (int l = 0; l < tree.num_levels(); ++l) {
    const int begin = tree.level_offset[static_cast<size_t>(l)],
              end = tree.level_offset[static_cast<size_t>(l) + 1];
    icd::SphereSet set;
    set.centers.resize(end - begin, 3);
    set.radii.resize(end - begin);
    for (int i = begin; i < end; ++i) {
      const auto& s = tree.spheres[static_cast<size_t>(i)];
      set.centers.row(i - begin) << s.x, s.y, s.z;
      set.radii[i - begin] = s.r;
    }
    icd::write_vtu_sphere_set(dir / (stem + "_level" + std::to_string(l) + ".vtu"), set);
  }
}

/// The `count` leaves with the largest 162-probe error: what limits the worst error.
void print_worst_leaves(const icd::SurfaceMesh& mesh, const icd::mesh::SphereTreeBuild& build,
                        double to_2000, int count) {
  const icd::mesh::MeshOracle oracle(icd::mesh::close_holes(mesh));
  const icd::MatX3d dirs = icd::mesh::probe_directions(2);
  const auto& tree = build.tree;
  const int leaf_level = tree.num_levels() - 1;
  std::vector<int> parent(static_cast<size_t>(tree.num_nodes()), -1);
  for (int i = 0; i < tree.num_nodes(); ++i) {
    for (int k = 0; k < tree.child_count[static_cast<size_t>(i)]; ++k)
      parent[static_cast<size_t>(tree.first_child[static_cast<size_t>(i)] + k)] = i;
  }
  std::vector<std::pair<double, int>> errors;
  for (int i = tree.level_offset[static_cast<size_t>(leaf_level)]; i < tree.num_nodes(); ++i) {
    const auto& s = tree.spheres[static_cast<size_t>(i)];
    double e = 0;
    for (Eigen::Index d = 0; d < dirs.rows(); ++d) {
      const Eigen::Vector3d p = s.center() + s.r * dirs.row(d).transpose();
      if (!oracle.inside(p)) e = std::max(e, oracle.distance(p));
    }
    errors.emplace_back(e * to_2000, i);
  }
  std::sort(errors.rbegin(), errors.rend());
  for (int k = 0; k < count && k < static_cast<int>(errors.size()); ++k) {
    const int i = errors[static_cast<size_t>(k)].second;
    const auto& s = tree.spheres[static_cast<size_t>(i)];
    const int p = parent[static_cast<size_t>(i)];
    std::printf(
        "# worst leaf %d: node %d error162 %.1f bound %.1f radius %.1f depth %.1f samples %zu, "
        "parent %d with %d children\n",
        k, i, errors[static_cast<size_t>(k)].first,
        to_2000 * (s.r - build.node_depth[static_cast<size_t>(i)]), to_2000 * s.r,
        to_2000 * build.node_depth[static_cast<size_t>(i)],
        build.node_samples[static_cast<size_t>(i)].size(), p,
        p >= 0 ? tree.child_count[static_cast<size_t>(p)] : 0);
  }
}

/// A copy of the tree whose leaves are re-polished against the 42 evaluation
/// directions themselves (search and acceptance): what fitting against the
/// probes of the metric does to it.
icd::collision::SphereTree fit_leaves_to_probes(const icd::SurfaceMesh& mesh,
                                                const icd::mesh::SphereTreeBuild& build) {
  const icd::mesh::MeshOracle oracle(icd::mesh::close_holes(mesh));
  const icd::mesh::MedialSpheres medial;  // unused by the polish
  const icd::mesh::PointGrid grid(build.samples.points.topRows(1), 1.0);
  const icd::mesh::ReductionProblem problem{build.samples.points, build.samples.gap, medial, grid};
  const icd::MatX3d probes = icd::mesh::probe_directions(1);
  icd::collision::SphereTree tree = build.tree;
  const int leaf_level = tree.num_levels() - 1;
  for (int i = tree.level_offset[static_cast<size_t>(leaf_level)]; i < tree.num_nodes(); ++i) {
    auto& s = tree.spheres[static_cast<size_t>(i)];
    icd::mesh::FittedSphere f;
    f.center = s.center();
    f.radius = s.r;
    f.members = build.node_samples[static_cast<size_t>(i)];
    icd::mesh::polish_protrusion_on(problem, oracle, f, probes, probes);
    s = {f.center.x(), f.center.y(), f.center.z(), f.radius};
    tree.rest_spheres[static_cast<size_t>(i)] = s;
  }
  return tree;
}

}  // namespace

int run(int argc, char** argv) {
  fs::path results;
  std::string models_arg = "bunny,dragon";
  icd::mesh::SphereTreeOptions options;
  options.branching = 8;
  options.depth = 3;
  options.max_spheres_per_level = {1, 8, 64, 445};
  bool with_octree = true;
  int diagnose = 0;
  bool fit_probes = false;
  double perturb = 0;
  bool canonical = false;
  icd::mesh::EvaluationOptions evaluation;
  using icd::experiments::Cli;
  Cli cli(
      "sphere_tree_table",
      "  Builds and evaluates the trees, writes .sph and VTU files into RESULTS_DIR\n"
      "  (see the comment at the top of sphere_tree_table.cpp and\n"
      "  experiments/studies/spheretree/results/README.md). The builder checks the ranges.");
  cli.argument("RESULTS_DIR", results, "output folder (created)", true);
  icd::mesh::SphereTreeOptions::Sampling& sampling = options.sampling;
  icd::mesh::SphereTreeOptions::Allocation& allocation = options.allocation;
  icd::mesh::SphereTreeOptions::Exchange& exchange = options.exchange;
  icd::mesh::WorstSplitOptions& split = options.worst_split.options;
  icd::mesh::ProtrusionPolishOptions& polish = options.polish.protrusion;
  std::vector<std::string> extra_meshes;
  cli.text("--models", models_arg, "bunny,dragon", "models to build ('' for none)")
      .custom("--mesh", "PATH",
              "also build this surface mesh (repeatable; named by its file stem)",
              [&extra_meshes](const std::string& v) { extra_meshes.push_back(v); })
      .real("--time-limit", options.time_limit, "S", "CPU budget of a build (s)")
      .real("--medial-spacing", sampling.medial_spacing, "REL", "medial sample spacing")
      .real("--cover-spacing", sampling.cover_spacing, "REL", "coverage sample spacing")
      .boolean("--joint", options.reduction.joint_leaf_refinement, "joint leaf refinement")
      .boolean("--regroup", allocation.regroup_parents, "choose the parents anew at the end")
      .integer("--lloyd", options.reduction.lloyd_iterations, "N", "Lloyd rounds of the reduction")
      .boolean("--octree", with_octree, "also the octree baseline")
      .real("--worst-share", allocation.worst_share, "F", "allocation: worst share")
      .real("--leaf-worst-target", allocation.leaf_worst_target, "REL", "leaf worst bound target")
      .real("--leaf-worst-factor", allocation.leaf_worst_factor, "F", "leaf worst bound factor")
      .real("--coverage-spacing", evaluation.coverage_spacing, "UNITS",
            "evaluation: dense coverage spacing")
      .integer("--shell-samples", evaluation.shell_samples, "N", "evaluation: points per sphere")
      .integer("--diagnose", diagnose, "N", "print the N leaves of largest 162-probe error", 0)
      .integer("--exchange-rounds", exchange.sibling_rounds, "N", "boundary exchange rounds")
      .integer("--relieve-moves", exchange.relieve_moves, "N", "relieve_worst moves")
      .boolean("--polish", options.polish.enabled, "protrusion polish")
      .integer("--polish-rounds", options.polish.exchange_rounds, "N",
               "exchange rounds of the polish")
      .integer("--polish-evals", polish.max_evaluations, "N", "polish evaluations per sphere")
      .integer("--polish-search", polish.search_directions, "N", "polish search directions")
      .integer("--polish-check", polish.check_directions, "N", "polish check directions")
      .boolean("--fit-probes", fit_probes,
               "also the leaves re-polished against the 42 evaluation directions")
      .integer("--sum-passes", exchange.sum_passes, "N", "lower_error_sum passes")
      .real("--sum-cap", exchange.sum_cap, "F", "lower_error_sum cap fraction")
      .real("--sum-share", exchange.sum_max_share, "F", "lower_error_sum receiver share")
      .real("--perturb", perturb, "E", "build for the mesh scaled by 1 + E")
      .boolean("--split-worst", options.worst_split.enabled, "split_worst_leaves")
      .integer("--split-tries", split.max_tries, "N", "split_worst: tries")
      .real("--split-relief", split.relief_fraction, "F", "split_worst: relief fraction")
      .real("--split-mean-rise", split.mean_rise_limit, "F", "split_worst: mean rise limit")
      .custom(
          "--caps", "1,8,64,N[,M]", "spheres allowed per level (depth = count - 1)",
          [&](const std::string& v) {
            std::vector<int> caps;
            std::stringstream list(v);
            for (std::string item; std::getline(list, item, ',');)
              caps.push_back(Cli::parse_integer<int>(item, 1));
            if (caps.size() < 2 || caps.front() != 1)
              throw std::invalid_argument(
                  "expects a list of positive counts starting with 1 (the root), got '" + v + "'");
            options.depth = static_cast<int>(caps.size()) - 1;
            options.max_spheres_per_level = caps;
          })
      .integer("--branching", options.branching, "B", "children per node at most")
      .integer("--build-branching", allocation.build_branching, "B",
               "SphereTreeOptions::Allocation::build_branching")
      .integer("--threads", options.threads, "N", "worker threads (0: all cores)", 0)
      .custom("--fit", "FIT",
              "icd-preprocess's --sphere-fit preset (light, full, shell); give it first: it "
              "resets the optimisation options given before it",
              [&](const std::string& v) {
                icd::mesh::apply_sphere_fit(icd::mesh::parse_sphere_fit(v, "--fit"), options);
              })
      .integer("--refinement", options.sampling.refinement_iterations, "N",
               "adaptive medial-axis rounds", 0)
      .boolean("--canonical", canonical,
               "build on the mesh in canonical order (as icd-preprocess does)")
      .custom("--flat", "N", "diagnostic: one level of at most N spheres under the root",
              [&](const std::string& v) {
                const int n = Cli::parse_integer<int>(v, 1);
                options.depth = 1;
                options.branching = std::max(2, n);
                options.max_spheres_per_level = {1, n};
              });
  if (const auto status = cli.parse(argc, argv)) return *status;
  fs::create_directories(results);
  const char* env = std::getenv("ICD_DATA_DIR");
  const fs::path data = env ? fs::path(env) : fs::path(ICD_DATA_DIR);
  std::vector<Model> models;
  std::stringstream ss(models_arg);
  for (std::string name; std::getline(ss, name, ',');) {
    if (name == "bunny") models.push_back({"bunny", "bunny00.off"});
    if (name == "dragon") models.push_back({"dragon", "ChineseDragon-10kv.off"});
  }
  // An absolute path replaces the data folder in `data / file` below.
  for (const std::string& m : extra_meshes)
    models.push_back({fs::path(m).stem().string(), fs::absolute(m).string()});

  icd::experiments::print_level_table_header();
  for (const auto& model : models) {
    const fs::path path = data / model.file;
    if (!fs::exists(path)) {
      std::fprintf(stderr, "missing %s (run scripts/fetch_meshes.sh); skipped\n",
                   path.string().c_str());
      continue;
    }
    const icd::SurfaceMesh mesh = icd::read_surface_mesh(path);

    const std::clock_t cpu0 = std::clock();
    // --perturb E: the tree is built for the mesh scaled by 1 + E (E ~ 1e-12
    // changes coordinates in their last bits only) and evaluated on the mesh:
    // how much the result depends on rounding.
    icd::SurfaceMesh build_mesh = canonical ? icd::mesh::canonical_order(mesh) : mesh;
    build_mesh.V *= 1.0 + perturb;
    const icd::mesh::SphereTreeBuild ours = icd::mesh::build_sphere_tree(build_mesh, options);
    const double build_cpu_s = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    icd::collision::validate(ours.tree);

    const auto t0 = std::chrono::steady_clock::now();
    icd::collision::OctreeTreeOptions octree_options;
    octree_options.levels = 4;
    const icd::collision::SphereTree octree =
        icd::collision::build_octree_tree(mesh.V, mesh.F, octree_options);
    const double octree_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    icd::experiments::print_level_table(
        model.name, "medial", ours.seconds,
        icd::mesh::evaluate_sphere_tree(mesh, ours.tree, evaluation));
    if (with_octree)
      icd::experiments::print_level_table(
          model.name, "octree", octree_s,
          icd::mesh::evaluate_sphere_tree(mesh, octree, evaluation));
    std::printf(
        "# %s: %lld coverage samples, %d medial spheres (%d refinement points), medial axis %.2f "
        "s, build CPU time %.1f s, wall %.1f s on %d threads (protrusion polish %.1f s, %d nodes "
        "moved)%s\n",
        model.name.c_str(), static_cast<long long>(ours.samples.points.rows()),
        ours.num_medial_spheres, ours.num_refinement_points, ours.medial_seconds, build_cpu_s,
        ours.seconds, icd::mesh::worker_count(options.threads), ours.polish_cpu_seconds,
        ours.num_polished, ours.hit_time_limit ? ", TIME LIMIT HIT" : "");
    // Model units -> the table's (longest bounding-box side 2000).
    const double to_2000 = icd::experiments::to_normalized_units(mesh);
    if (options.worst_split.enabled) {
      const auto& w = ours.worst_split;
      std::printf(
          "# %s worst split: %d splits in %d tries (%d merges; %d worst leaves with a full parent; "
          "relief band: %d without two better halves, %d without a merge), %d spheres measured, "
          "true worst (%d dirs) %.1f -> %.1f, mean at the start (%d dirs) %.2f\n",
          model.name.c_str(), w.splits, w.tries, w.merges, w.blocked_by_parent, w.relief_no_split,
          w.relief_no_merge, w.measured, split.measure_directions, to_2000 * w.worst_before,
          to_2000 * w.worst_after, split.choice_directions, to_2000 * w.mean_before);
    }
    std::printf("# %s allocation: largest worst child bound chosen per level (medial samples):",
                model.name.c_str());
    for (size_t l = 0; l < ours.allocated_worst_bound.size(); ++l)
      std::printf(" %zu: %.1f;", l + 1, to_2000 * ours.allocated_worst_bound[l]);
    std::printf("\n");
    std::printf("# %s build steps (CPU s / wall s):", model.name.c_str());
    for (size_t k = 0; k < ours.step_cpu_seconds.size(); ++k)
      std::printf(" %s %.1f / %.1f;", ours.step_cpu_seconds[k].first.c_str(),
                  ours.step_cpu_seconds[k].second, ours.step_wall_seconds[k].second);
    std::printf("\n");
    // The builder's own error bound (radius - centre depth), normalized, per level.
    for (int l = 0; l < ours.tree.num_levels(); ++l) {
      double worst = 0, sum = 0;
      const int begin = ours.tree.level_offset[static_cast<size_t>(l)],
                end = ours.tree.level_offset[static_cast<size_t>(l) + 1];
      for (int i = begin; i < end; ++i) {
        const double bound = to_2000 * (ours.tree.spheres[static_cast<size_t>(i)].r -
                                        ours.node_depth[static_cast<size_t>(i)]);
        worst = std::max(worst, bound), sum += bound;
      }
      std::printf("# %s level %d: error bound r - depth: worst %.1f mean %.2f\n",
                  model.name.c_str(), l, worst, sum / (end - begin));
    }
    if (diagnose > 0) print_worst_leaves(mesh, ours, to_2000, diagnose);
    icd::experiments::print_dense_errors(model.name, mesh, ours.tree, to_2000);
    if (fit_probes) {
      const icd::collision::SphereTree fitted = fit_leaves_to_probes(mesh, ours);
      icd::experiments::print_level_table(
          model.name, "fit42", 0.0, icd::mesh::evaluate_sphere_tree(mesh, fitted, evaluation));
      icd::experiments::print_dense_errors(model.name + " fit42", mesh, fitted, to_2000);
    }
    std::fflush(stdout);
    write_tree(results, model.name + "_medial", ours.tree);
    write_tree(results, model.name + "_octree", octree);
  }
  return 0;
}

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("sphere_tree_table", run, argc, argv);
}
