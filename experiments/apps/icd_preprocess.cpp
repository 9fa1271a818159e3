// icd-preprocess: raw dense surface -> simulation-ready asset bundle (issue 4).
//   icd-preprocess dense.off -o assets/dragon --coarse-tets 2000
// Run with --help for the options. Exit status 0 on success, 1 on bad input
// (the message says what and where), 2 on bad command-line options.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>
#include <variant>
#include <vector>

#include <icd/collision/sph_io.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/pipeline/preprocess.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"

namespace {

using icd::mesh::PreprocessOptions;

// The footer of --help: what the program does and the defaults it gets from
// the library's options.
std::string help_footer(const PreprocessOptions& d) {
  char defaults[1024];
  std::snprintf(
      defaults, sizeof defaults,
      "  Defaults: --coarse-tets %d, --simplify-faces %d, --max-hole-edges %d,\n"
      "  --max-hole-diameter %g, --max-surface-change %g, --wrap-alpha %g,\n"
      "  --max-wrap-distance %g, --radius-edge %g,\n"
      "  --facet-distance %g, --feature-angle %g, --sliver-bound %g, --step-target %g,\n"
      "  --spheres medial, --sphere-depth %d, --sphere-branching %d, --sphere-fit light,\n"
      "  --assoc-nearest %d,"
      " --time-limit %g, --memory-limit %g.\n",
      d.tetrahedralize.target_tets, d.simplify.target_faces, d.repair.max_hole_edges,
      d.repair.max_hole_diameter, d.repair.max_surface_change, d.repair.wrap_alpha,
      d.repair.max_wrap_distance, d.tetrahedralize.radius_edge_bound,
      d.tetrahedralize.facet_distance_factor, d.tetrahedralize.feature_angle_deg,
      d.tetrahedralize.sliver_bound_deg, d.tetrahedralize.step_cleanup.target_ratio,
      d.spheres.depth, d.spheres.branching, d.association.k_nearest, d.limits.cpu_seconds,
      d.limits.memory_mb);
  return std::string(
             "  Prepares a deformable object: repairs the dense surface INPUT (.off .obj .ply\n"
             "  .stl), simplifies it with quadric error metrics, tetrahedralizes it into the\n"
             "  coarse mesh, ties every dense vertex to the coarse surface by a rigid link, builds\n"
             "  the sphere tree and its node associations, and writes the asset bundle to FOLDER:\n"
             "  dense_surface.vtu, coarse_tets.vtu (ParaView/meshio), bundle.icdb (links,\n"
             "  spheres). Same input and options give byte-identical files.\n") +
         defaults;
}

struct Command {
  std::string input, output;
  PreprocessOptions options;
  icd::mesh::SphereFit fit = icd::mesh::SphereFit::light;
  std::string sph;  ///< --sph: the tree as .sph too (empty: no)
  bool quiet = false;
};

// The command line, or the exit status to return (0 after --help or
// --version, 2 on a bad command line).
std::variant<Command, int> parse(int argc, char** argv) {
  using icd::experiments::Cli;
  Command c;
  auto& o = c.options;
  bool simplify_faces = false, simplify_ratio = false, no_spheres = false, no_hausdorff = false;
  std::string fit_option, spheres_option;
  double cell_size = o.tetrahedralize.cell_size, ratio = o.simplify.target_ratio;
  Cli cli("icd-preprocess", help_footer(PreprocessOptions{}));
  cli.argument("INPUT", "dense surface mesh (.off .obj .ply .stl)", true,
               [&c](const std::string& v) { c.input = v; });
  cli.text("-o,--output", c.output, "FOLDER", "bundle folder (created) [required]")
      .integer("--coarse-tets", o.tetrahedralize.target_tets, "N", "target number of coarse tets")
      .real("--cell-size", cell_size, "H",
            "fixed tet size (circumradius bound, model units); overrides --coarse-tets")
      .custom("--simplify-faces", "N", "faces of the simplified surface",
              [&](const std::string& v) {
                o.simplify.target_faces = Cli::parse_integer<int>(v);
                simplify_faces = true;
              })
      .custom("--simplify-ratio", "R", "or a fraction of the input faces, in (0, 1]",
              [&](const std::string& v) {
                ratio = Cli::parse_real(v);
                simplify_ratio = true;
              })
      .integer("--max-hole-edges", o.repair.max_hole_edges, "N",
               "fill holes with at most N boundary edges")
      .real("--max-hole-diameter", o.repair.max_hole_diameter, "F",
            "... and diameter at most F * bbox diagonal")
      .real("--max-surface-change", o.repair.max_surface_change, "F",
            "largest area/volume change of a local self-intersection repair, relative")
      .custom("--wrap", "WHEN",
              "rebuild the surface by alpha wrapping: fallback (when repair would refuse it: "
              "a non-manifold edge, unresolved self-intersections), always, never",
              [&](const std::string& v) {
                try {
                  o.repair.wrap = icd::mesh::parse_wrap(v, "--wrap");
                } catch (const icd::ParameterError&) {
                  throw std::invalid_argument("must be never, fallback or always, got '" + v +
                                              "'");
                }
              })
      .real("--wrap-alpha", o.repair.wrap_alpha, "F",
            "alpha of the wrap, F * bbox diagonal (smaller: closer to the input, more faces)")
      .custom("--max-wrap-distance", "F",
              "refuse a wrap farther than F * bbox diagonal from the input, in (0, 1] (a wrap "
              "that closes holes lies about their radius away)",
              [&](const std::string& v) {
                o.repair.max_wrap_distance = Cli::parse_real(v);
                if (!(o.repair.max_wrap_distance > 0 && o.repair.max_wrap_distance <= 1))
                  throw std::invalid_argument("must be in (0, 1], got '" + v + "'");
              })
      .real("--radius-edge", o.tetrahedralize.radius_edge_bound, "B",
            "tet radius-edge ratio bound, >= 2")
      .real("--interior-size", o.tetrahedralize.interior_size_factor, "F",
            "cell size inside = F x the surface's, in (0, 1] (smaller: more interior nodes)")
      .real("--facet-distance", o.tetrahedralize.facet_distance_factor, "F",
            "surface approximation bound, F * cell size")
      .real("--feature-angle", o.tetrahedralize.feature_angle_deg, "DEG",
            "protect edges sharper than DEG (0: none)")
      .real("--sliver-bound", o.tetrahedralize.sliver_bound_deg, "DEG",
            "dihedral angle targeted by perturb/exude")
      .real("--step-target", o.tetrahedralize.step_cleanup.target_ratio, "R",
            "collapse the nodes that hold the explicit-FEM stable step below R x that of "
            "near-regular tets (0: off)")
      .custom("--spheres", "KIND",
              "sphere-tree builder: medial (adaptive medial axis), octree, none",
              [&](const std::string& k) {
                if (k == "medial")
                  o.sphere_builder = icd::mesh::SphereBuilder::medial_axis;
                else if (k == "octree")
                  o.sphere_builder = icd::mesh::SphereBuilder::octree;
                else if (k == "none")
                  o.sphere_builder = icd::mesh::SphereBuilder::none;
                else
                  throw std::invalid_argument("must be medial, octree or none, got '" + k + "'");
              })
      .flag("--no-spheres", no_spheres, "same as --spheres none")
      .custom("--sphere-depth", "D", "sphere-tree levels below the root",
              [&](const std::string& v) {
                o.spheres.depth = Cli::parse_integer<int>(v);
                o.octree.levels = o.spheres.depth + 1;
              })
      .integer("--sphere-branching", o.spheres.branching, "B", "children per sphere")
      .text("--sphere-fit", fit_option, "FIT",
            "medial tree optimisation: light, full (the builder's defaults), shell (thinnest "
            "leaf shell)")
      .text("--sph", c.sph, "FILE", "also write the sphere tree (rest pose) as .sph to FILE")
      .real("--sphere-time-limit", o.spheres.time_limit, "S",
            "CPU seconds for the medial-axis optimisation [none]; a limit that fires makes the "
            "output machine-load dependent")
      .integer("--assoc-nearest", o.association.k_nearest, "K",
               "coarse nodes associated with each sphere, at least")
      .flag("--no-hausdorff", no_hausdorff, "skip the Hausdorff distance of the summary")
      .custom("--time-limit", "S", "CPU seconds each stage may use",
              [&](const std::string& v) {
                o.limits.cpu_seconds = Cli::parse_real(v);
                if (!(o.limits.cpu_seconds > 0)) throw std::invalid_argument("must be > 0");
              })
      .custom("--memory-limit", "MB", "memory each stage may use, MiB",
              [&](const std::string& v) {
                o.limits.memory_mb = Cli::parse_real(v);
                if (!(o.limits.memory_mb > 0)) throw std::invalid_argument("must be > 0");
              })
      .flag("-q,--quiet", c.quiet, "only errors and the final summary");
  if (const auto status = cli.parse(argc, argv)) return *status;
  const auto fail = [](const std::string& what) { return Cli::fail("icd-preprocess", what); };
  o.tetrahedralize.cell_size = cell_size;
  if (!(o.tetrahedralize.step_cleanup.target_ratio >= 0))
    return fail("--step-target must be >= 0 (0: no post-pass)");
  if (simplify_faces && simplify_ratio)
    return fail("--simplify-faces and --simplify-ratio contradict each other: give one");
  if (simplify_ratio) {
    o.simplify.target_faces = 0;
    o.simplify.target_ratio = ratio;
  }
  if (no_spheres) o.sphere_builder = icd::mesh::SphereBuilder::none;
  if (no_hausdorff) o.compute_hausdorff = false;
  if (!fit_option.empty()) {
    try {
      c.fit = icd::mesh::parse_sphere_fit(fit_option, "--sphere-fit");
    } catch (const icd::ParameterError& e) {
      return fail(e.what());
    }
    if (o.sphere_builder != icd::mesh::SphereBuilder::medial_axis)
      return fail(std::string("--sphere-fit and ") +
                  (o.sphere_builder == icd::mesh::SphereBuilder::octree ? "--spheres octree"
                                                                        : "--spheres none") +
                  " contradict each other: --sphere-fit optimises a medial tree");
  }
  icd::mesh::apply_sphere_fit(c.fit, o.spheres);  // after the options: keeps --sphere-depth etc.
  if (!c.sph.empty() && o.sphere_builder == icd::mesh::SphereBuilder::none)
    return fail("--sph needs a sphere tree (not --spheres none)");
  if (c.output.empty()) return fail("no output folder (-o)");
  return c;
}

void print_summary(const Command& c, const icd::mesh::PreprocessResult& r, double write_s,
                   double load_ms, double load_cpu_ms) {
  const auto& b = r.bundle;
  std::printf("\n== icd-preprocess summary: %s -> %s\n", c.input.c_str(), c.output.c_str());
  std::printf("-- repair\n%s", r.repair.to_string().c_str());
  std::printf("-- simplify: %d -> %d faces (%d edge collapses)\n", r.simplify.input_faces,
              r.simplify.output_faces, r.simplify.collapsed_edges);
  std::printf("-- coarse tet mesh (cell size %.4g, %d mesher pass(es))\n%s", r.cell_size,
              r.mesher_passes, r.quality.to_string().c_str());
  std::printf("-- %s\n", r.stable_step.to_string(c.options.stable_step).c_str());
  const std::string fem_warnings =
      icd::mesh::fem_quality_warnings(r.stable_step, r.quality.min_dihedral_deg);
  if (!fem_warnings.empty())
    std::printf("-- WARNING: tets not fit for explicit FEM: %s (thin parts whose light surface "
                "nodes the --step-target post-pass could not remove; see "
                "experiments/studies/preprocess/README.md, stable step)\n",
                fem_warnings.c_str());
  {
    // Fidelity of the coarse mesh (issue 30 item 6; targets as in
    // experiments/studies/preprocess/README.md).
    const auto& q = r.quality;
    const double dv = r.repair.volume > 0 ? q.total_volume / r.repair.volume - 1.0 : 0.0;
    const int interior = q.num_vertices - q.num_surface_nodes;
    const double share = q.num_vertices > 0 ? static_cast<double>(interior) / q.num_vertices : 0;
    const int target = c.options.tetrahedralize.cell_size > 0 ? 0 : c.options.tetrahedralize.target_tets;
    const double dt = target > 0 ? static_cast<double>(q.num_tets) / target - 1.0 : 0.0;
    const double h = r.hausdorff_dense_coarse >= 0 ? r.hausdorff_dense_coarse / r.bbox_diagonal : -1;
    std::printf("-- fidelity: volume %+.2f %% of the repaired surface's, ", 100.0 * dv);
    if (h >= 0) std::printf("Hausdorff %.2f %% of the diagonal, ", 100.0 * h);
    if (target > 0) std::printf("%d tets for %d requested (%+.0f %%), ", q.num_tets, target, 100.0 * dt);
    std::printf("%d interior nodes (%.1f %% of %d)\n", interior, 100.0 * share, q.num_vertices);
    std::string miss;
    const auto add = [&miss](const std::string& m) { miss += (miss.empty() ? "" : "; ") + m; };
    if (std::abs(dv) > 0.05) add("volume changed by more than 5 %");
    if (h > 0.03) add("Hausdorff distance above 3 % of the diagonal (--coarse-tets more)");
    if (target > 0 && std::abs(dt) > 0.25) add("tet count more than 25 % off the request");
    if (share < 0.10)
      add("under 10 % of the nodes inside: thick parts have few nodes to deform (--interior-size 0.6)");
    if (!miss.empty()) std::printf("-- WARNING: fidelity target missed: %s\n", miss.c_str());
  }
  std::printf("-- rigid links: %d dense vertices on %d coarse surface nodes\n", b.links.num_links(),
              static_cast<int>(b.surface_nodes.size()));
  if (c.options.sphere_builder != icd::mesh::SphereBuilder::none) {
    std::printf(
        "-- sphere tree (%s%s): %d spheres, %d levels, %zu node associations%s\n",
        c.options.sphere_builder == icd::mesh::SphereBuilder::octree ? "octree"
        : r.sphere_fallback.empty() ? "medial axis"
                                    : "octree, the medial-axis builder's fallback",
        c.options.sphere_builder == icd::mesh::SphereBuilder::octree || !r.sphere_fallback.empty()
            ? ""
            : (std::string(", fit ") + icd::mesh::to_string(c.fit)).c_str(),
        b.spheres.num_nodes(), r.sphere_levels, b.spheres.assoc_nodes.size(),
        r.sphere_time_limit_hit ? " (TIME LIMIT HIT: output may differ between runs)" : "");
  } else {
    std::printf("-- sphere tree: skipped (--spheres none)\n");
  }
  if (r.hausdorff_dense_coarse >= 0)
    std::printf(
        "-- Hausdorff distance (approx.): dense-simplified %.4g, dense-coarse %.4g (%.3g%% of the "
        "bbox diagonal %.4g)\n",
        r.hausdorff_dense_simplified, r.hausdorff_dense_coarse,
        100.0 * r.hausdorff_dense_coarse / r.bbox_diagonal, r.bbox_diagonal);
  std::printf("-- time per stage, wall (cpu) s [peak MB]:");
  double total = 0, total_cpu = 0, peak = 0;
  for (const auto& t : r.times) {
    std::printf(" %s %.2f (%.2f) [%.0f],", t.stage.c_str(), t.seconds, t.cpu_seconds, t.peak_mb);
    total += t.seconds;
    total_cpu += t.cpu_seconds;
    peak = std::max(peak, t.peak_mb);
  }
  std::printf(" write %.2f; total %.2f (%.2f), peak %.0f MB\n", write_s, total + write_s,
              total_cpu, peak);
  for (const auto& n : r.notes) std::printf("-- note: %s\n", n.c_str());
  std::printf("-- bundle load check: %.1f ms wall, %.1f ms cpu (medians of 5 loads)\n", load_ms,
              load_cpu_ms);
}

// The program; throws on bad input (main() reports it).
int run(int argc, char** argv) {
  const auto parsed = parse(argc, argv);
  if (const int* status = std::get_if<int>(&parsed)) return *status;
  const Command& cli = std::get<Command>(parsed);
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  icd::ReadReport read_report;
  const icd::SurfaceMesh dense = icd::read_surface_mesh(cli.input, &read_report);
  for (const std::string& w : read_report.warnings)  // even with --quiet
    std::fprintf(stderr, "icd-preprocess: warning: %s: %s\n", cli.input.c_str(), w.c_str());
  if (!cli.quiet)
    std::printf("[read] %s: %s, %lld vertices, %lld triangles (%.2f s)\n", cli.input.c_str(),
                read_report.format.c_str(), static_cast<long long>(read_report.vertices),
                static_cast<long long>(read_report.triangles),
                std::chrono::duration<double>(Clock::now() - t0).count());
  const int num_stages = 4 +
                         (cli.options.sphere_builder != icd::mesh::SphereBuilder::none ? 1 : 0) +
                         (cli.options.compute_hausdorff ? 1 : 0);
  int stage_index = 0;
  const icd::mesh::ProgressFn progress = [&](const std::string& stage, const std::string& msg) {
    if (cli.quiet) return;
    if (msg == "start") {
      std::printf("[%d/%d] %s ...\n", ++stage_index, num_stages, stage.c_str());
    } else {
      std::printf("[%d/%d] %s: %s\n", stage_index, num_stages, stage.c_str(), msg.c_str());
    }
    std::fflush(stdout);
  };
  const icd::mesh::PreprocessResult r =
      icd::mesh::preprocess(dense, cli.options, progress, cli.input);

  const auto tw = Clock::now();
  icd::coupling::write_asset_bundle(cli.output, r.bundle);
  if (!cli.sph.empty()) {  // under a temporary name until complete
    const std::string part = cli.sph + ".part";
    try {
      icd::collision::write_sph(part, r.bundle.spheres);
    } catch (...) {
      std::filesystem::remove(part);
      throw;
    }
    std::filesystem::rename(part, cli.sph);
  }
  const double write_s = std::chrono::duration<double>(Clock::now() - tw).count();
  std::vector<double> load_ms, load_cpu_ms;
  for (int i = 0; i < 5; ++i) {
    const auto tl = Clock::now();
    const std::clock_t cl = std::clock();
    const icd::coupling::AssetBundle loaded = icd::coupling::read_asset_bundle(cli.output);
    load_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - tl).count());
    load_cpu_ms.push_back(1000.0 * static_cast<double>(std::clock() - cl) / CLOCKS_PER_SEC);
    if (loaded.links.num_links() != r.bundle.links.num_links()) {
      std::fprintf(stderr, "icd-preprocess: the written bundle does not read back\n");
      return 1;
    }
  }
  std::sort(load_ms.begin(), load_ms.end());
  std::sort(load_cpu_ms.begin(), load_cpu_ms.end());
  print_summary(cli, r, write_s, load_ms[2], load_cpu_ms[2]);
  return 0;
}

}  // namespace

// A ParameterError (an option value the pipeline refuses) is bad usage:
// "icd-preprocess: invalid option: ...", status 2.
int main(int argc, char** argv) {
  return icd::experiments::guarded_main<icd::ParameterError>("icd-preprocess", run, argc, argv);
}
