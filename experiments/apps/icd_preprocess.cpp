// icd-preprocess: raw dense surface -> simulation-ready asset bundle (issue 4).
//   icd-preprocess dense.off -o assets/dragon --coarse-tets 2000
// Run with --help for the options. Exit status 0 on success, 1 on bad input
// (the message says what and where), 2 on bad command-line options.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <icd/collision/sph_io.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/pipeline/preprocess.hpp>

namespace {

using icd::mesh::PreprocessOptions;

void print_help(const PreprocessOptions& d) {
  std::printf(
      "usage: icd-preprocess INPUT -o FOLDER [options]\n"
      "\n"
      "Prepares a deformable object: repairs the dense surface INPUT (.off .obj .ply .stl),\n"
      "simplifies it with quadric error metrics, tetrahedralizes it into the coarse mesh,\n"
      "ties every dense vertex to the coarse surface by a rigid link, builds the sphere tree\n"
      "and its node associations, and writes the asset bundle to FOLDER:\n"
      "  dense_surface.vtu, coarse_tets.vtu (ParaView/meshio), bundle.icdb (links, spheres).\n"
      "Same input and options give byte-identical files.\n"
      "\n"
      "options (defaults in brackets):\n"
      "  -o, --output FOLDER        bundle folder (created) [required]\n"
      "  --coarse-tets N            target number of coarse tets [%d]\n"
      "  --cell-size H              fixed tet size (circumradius bound, model units); overrides "
      "--coarse-tets\n"
      "  --simplify-faces N         faces of the simplified surface [%d]\n"
      "  --simplify-ratio R         or a fraction of the input faces, in (0, 1]\n"
      "  --max-hole-edges N         fill holes with at most N boundary edges [%d]\n"
      "  --max-hole-diameter F      ... and diameter at most F * bbox diagonal [%g]\n"
      "  --max-surface-change F     largest area/volume change of a local self-intersection\n"
      "                             repair, relative [%g]\n"
      "  --radius-edge B            tet radius-edge ratio bound, >= 2 [%g]\n"
      "  --facet-distance F         surface approximation bound, F * cell size [%g]\n"
      "  --feature-angle DEG        protect edges sharper than DEG (0: none) [%g]\n"
      "  --sliver-bound DEG         dihedral angle targeted by perturb/exude [%g]\n"
      "  --spheres KIND             sphere-tree builder: medial (adaptive medial axis), octree, "
      "none [medial]\n"
      "  --no-spheres               same as --spheres none\n"
      "  --sphere-depth D           sphere-tree levels below the root [%d]\n"
      "  --sphere-branching B       children per sphere [%d]\n"
      "  --sphere-fit FIT           medial tree optimisation: light, full (the builder's "
      "defaults),\n"
      "                             shell (thinnest leaf shell) [light]\n"
      "  --sph FILE                 also write the sphere tree (rest pose) as .sph to FILE\n"
      "  --sphere-time-limit S      CPU seconds for the medial-axis optimisation [none];\n"
      "                             a limit that fires makes the output machine-load dependent\n"
      "  --assoc-nearest K          coarse nodes associated with each sphere, at least [%d]\n"
      "  --no-hausdorff             skip the Hausdorff distance of the summary\n"
      "  --time-limit S             CPU seconds each stage may use [%g]\n"
      "  --memory-limit MB          memory each stage may use, MiB [%g]\n"
      "  -q, --quiet                only errors and the final summary\n"
      "  -h, --help                 this text\n",
      d.tetrahedralize.target_tets, d.simplify.target_faces, d.repair.max_hole_edges,
      d.repair.max_hole_diameter, d.repair.max_surface_change, d.tetrahedralize.radius_edge_bound,
      d.tetrahedralize.facet_distance_factor, d.tetrahedralize.feature_angle_deg,
      d.tetrahedralize.sliver_bound_deg, d.spheres.depth,
      d.spheres.branching, d.association.k_nearest, d.limits.cpu_seconds, d.limits.memory_mb);
}

struct Cli {
  std::string input, output;
  PreprocessOptions options;
  icd::mesh::SphereFit fit = icd::mesh::SphereFit::light;
  std::string sph;  ///< --sph: the tree as .sph too (empty: no)
  bool quiet = false;
};

[[noreturn]] void usage_error(const std::string& msg) {
  std::fprintf(stderr, "icd-preprocess: %s (see --help)\n", msg.c_str());
  std::exit(2);
}

double to_double(const std::string& opt, const std::string& v) {
  try {
    std::size_t used = 0;
    const double x = std::stod(v, &used);
    if (used == v.size()) return x;
  } catch (const std::exception&) {
  }
  usage_error(opt + " needs a number, got '" + v + "'");
}

int to_int(const std::string& opt, const std::string& v) {
  try {
    std::size_t used = 0;
    const int x = std::stoi(v, &used);
    if (used == v.size()) return x;
  } catch (const std::exception&) {
  }
  usage_error(opt + " needs an integer, got '" + v + "'");
}

Cli parse(int argc, char** argv) {
  Cli c;
  auto& o = c.options;
  std::vector<std::string> args(argv + 1, argv + argc);
  std::string faces_option, fit_option;  // for the contradiction checks below
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) usage_error(a + " needs a value");
      return args[++i];
    };
    if (a == "-h" || a == "--help") {
      print_help(PreprocessOptions{});
      std::exit(0);
    } else if (a == "-o" || a == "--output") {
      c.output = value();
    } else if (a == "--coarse-tets") {
      o.tetrahedralize.target_tets = to_int(a, value());
    } else if (a == "--cell-size") {
      o.tetrahedralize.cell_size = to_double(a, value());
    } else if (a == "--simplify-faces") {
      o.simplify.target_faces = to_int(a, value());
      if (faces_option == "--simplify-ratio")
        usage_error("--simplify-faces and --simplify-ratio contradict each other: give one");
      faces_option = a;
    } else if (a == "--simplify-ratio") {
      if (faces_option == "--simplify-faces")
        usage_error("--simplify-faces and --simplify-ratio contradict each other: give one");
      faces_option = a;
      o.simplify.target_faces = 0;
      o.simplify.target_ratio = to_double(a, value());
    } else if (a == "--max-hole-edges") {
      o.repair.max_hole_edges = to_int(a, value());
    } else if (a == "--max-hole-diameter") {
      o.repair.max_hole_diameter = to_double(a, value());
    } else if (a == "--max-surface-change") {
      o.repair.max_surface_change = to_double(a, value());
    } else if (a == "--radius-edge") {
      o.tetrahedralize.radius_edge_bound = to_double(a, value());
    } else if (a == "--facet-distance") {
      o.tetrahedralize.facet_distance_factor = to_double(a, value());
    } else if (a == "--feature-angle") {
      o.tetrahedralize.feature_angle_deg = to_double(a, value());
    } else if (a == "--sliver-bound") {
      o.tetrahedralize.sliver_bound_deg = to_double(a, value());
    } else if (a == "--spheres") {
      const std::string& k = value();
      if (k == "medial") {
        o.sphere_builder = icd::mesh::SphereBuilder::medial_axis;
      } else if (k == "octree") {
        o.sphere_builder = icd::mesh::SphereBuilder::octree;
      } else if (k == "none") {
        o.sphere_builder = icd::mesh::SphereBuilder::none;
      } else {
        usage_error("--spheres must be medial, octree or none, got '" + k + "'");
      }
    } else if (a == "--no-spheres") {
      o.sphere_builder = icd::mesh::SphereBuilder::none;
    } else if (a == "--sphere-depth") {
      o.spheres.depth = to_int(a, value());
      o.octree.levels = o.spheres.depth + 1;
    } else if (a == "--sphere-branching") {
      o.spheres.branching = to_int(a, value());
    } else if (a == "--sphere-fit") {
      fit_option = a;
      const std::string& f = value();
      try {
        c.fit = icd::mesh::parse_sphere_fit(f, "--sphere-fit");
      } catch (const icd::ParameterError& e) {
        usage_error(e.what());
      }
    } else if (a == "--sph") {
      c.sph = value();
    } else if (a == "--sphere-time-limit") {
      o.spheres.time_limit = to_double(a, value());
    } else if (a == "--assoc-nearest") {
      o.association.k_nearest = to_int(a, value());
    } else if (a == "--time-limit") {
      o.limits.cpu_seconds = to_double(a, value());
      if (!(o.limits.cpu_seconds > 0)) usage_error("--time-limit must be > 0");
    } else if (a == "--memory-limit") {
      o.limits.memory_mb = to_double(a, value());
      if (!(o.limits.memory_mb > 0)) usage_error("--memory-limit must be > 0");
    } else if (a == "--no-hausdorff") {
      o.compute_hausdorff = false;
    } else if (a == "-q" || a == "--quiet") {
      c.quiet = true;
    } else if (!a.empty() && a[0] == '-') {
      usage_error("unknown option " + a);
    } else if (c.input.empty()) {
      c.input = a;
    } else {
      usage_error("more than one input file ('" + c.input + "', '" + a + "')");
    }
  }
  if (!fit_option.empty() && o.sphere_builder != icd::mesh::SphereBuilder::medial_axis)
    usage_error(std::string("--sphere-fit and ") +
                (o.sphere_builder == icd::mesh::SphereBuilder::octree ? "--spheres octree"
                                                                      : "--spheres none") +
                " contradict each other: --sphere-fit optimises a medial tree");
  icd::mesh::apply_sphere_fit(c.fit, o.spheres);  // after the loop: keeps --sphere-depth etc.
  if (!c.sph.empty() && o.sphere_builder == icd::mesh::SphereBuilder::none)
    usage_error("--sph needs a sphere tree (not --spheres none)");
  if (c.input.empty()) usage_error("no input file");
  if (c.output.empty()) usage_error("no output folder (-o)");
  return c;
}

void print_summary(const Cli& c, const icd::mesh::PreprocessResult& r, double write_s,
                   double load_ms, double load_cpu_ms) {
  const auto& b = r.bundle;
  std::printf("\n== icd-preprocess summary: %s -> %s\n", c.input.c_str(), c.output.c_str());
  std::printf("-- repair\n%s", r.repair.to_string().c_str());
  std::printf("-- simplify: %d -> %d faces (%d edge collapses)\n", r.simplify.input_faces,
              r.simplify.output_faces, r.simplify.collapsed_edges);
  std::printf("-- coarse tet mesh (cell size %.4g, %d mesher pass(es))\n%s", r.cell_size,
              r.mesher_passes, r.quality.to_string().c_str());
  std::printf("-- rigid links: %d dense vertices on %d coarse surface nodes\n", b.links.num_links(),
              static_cast<int>(b.surface_nodes.size()));
  if (c.options.sphere_builder != icd::mesh::SphereBuilder::none) {
    std::printf(
        "-- sphere tree (%s%s): %d spheres, %d levels, %zu node associations%s\n",
        c.options.sphere_builder == icd::mesh::SphereBuilder::octree ? "octree" : "medial axis",
        c.options.sphere_builder == icd::mesh::SphereBuilder::octree
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

}  // namespace

int main(int argc, char** argv) {
  const Cli cli = parse(argc, argv);
  using Clock = std::chrono::steady_clock;
  try {
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
  } catch (const icd::ParameterError& e) {
    std::fprintf(stderr, "icd-preprocess: invalid option: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "icd-preprocess: %s\n", e.what());
    return 1;
  }
  return 0;
}
