// deformation_error: error of the dense surface against run time for the two
// approximations of the deformation (paper section 3):
//  1. rigid links (Eqs. 1, 9, 10) vs the barycentric embedding of the dense
//     vertices in the coarse tets (the reference mapping), on the same coarse
//     motion: per frame, per object, RMS and max distance between the two
//     dense surfaces (m and % of the dense bounding-box diagonal) and the time
//     of each mapping (median of --reps evaluations).
//  2. coarse resolution vs a fine-mesh reference: a scene of primitive objects
//     (same dense icosphere, coarse grids of --cells cells per side) is run
//     with each resolution and with --fine cells; the dense positions of the
//     first object are compared vertex by vertex with the fine run's at every
//     frame (links on every run). Time per frame: median wall time of a frame.
// Writes links.csv and resolution.csv into --out.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <icd/config.hpp>
#include <icd/coupling/barycentric_embedding.hpp>
#include <icd/coupling/rigid_links.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/atomic_write.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/studies/paper/contact_moment.hpp"

namespace fs = std::filesystem;
using namespace icd;
using namespace icd::runner;
using experiments::median;
using experiments::seconds_since;

namespace {

double bbox_diagonal(const MatX3d& V) {
  return (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
}

struct Error {
  double rms = 0, max = 0;
};

Error compare(const MatX3d& x, const MatX3d& y) {
  const Eigen::VectorXd d = (x - y).rowwise().norm();
  if (!d.allFinite()) throw NumericalError("deformation_error: non-finite dense positions");
  return {std::sqrt(d.squaredNorm() / double(d.size())), d.maxCoeff()};
}

void links_vs_barycentric(const Scene& scene, int frames, int reps, std::ostringstream& csv) {
  World world = make_world(scene, fs::path(ICD_SOURCE_DIR) / "assets",
              fs::canonical("/proc/self/exe").parent_path());
  std::vector<coupling::BarycentricEmbedding> emb;
  std::vector<double> diag;
  for (const RuntimeObject& o : world.objects()) {
    emb.push_back(coupling::build_barycentric_embedding(o.asset.dense.V, o.rest, o.asset.coarse.T));
    diag.push_back(bbox_diagonal(o.asset.dense.V));
  }
  for (int f = 0; f < frames; ++f) {
    FrameMetrics m;
    try {
      m = world.step();
    } catch (const std::exception& e) {
      // Keep the frames measured so far; the failure is the simulation's, not the mapping's.
      std::fprintf(stderr, "deformation_error: %s stopped at frame %d (links rows kept): %s\n",
                   scene.name.c_str(), f, e.what());
      return;
    }
    for (size_t k = 0; k < world.objects().size(); ++k) {
      const RuntimeObject& o = world.objects()[k];
      if (!o.sim) continue;  // rigid and static objects do not deform
      MatX3d links(o.asset.dense.V.rows(), 3), bary(o.asset.dense.V.rows(), 3);
      std::vector<double> tl, tb;
      for (int r = 0; r < reps; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        coupling::apply(o.asset.links, o.positions, links);
        tl.push_back(seconds_since(t0));
        t0 = std::chrono::steady_clock::now();
        coupling::apply(emb[k], o.positions, bary);
        tb.push_back(seconds_since(t0));
      }
      const Error e = compare(links, bary);
      csv << scene.name << ',' << f << ',' << o.setup.name << ',' << o.asset.dense.V.rows() << ','
          << o.rest.rows() << ',' << emb[k].num_outside << ',' << median(tl) << ',' << median(tb)
          << ',' << e.rms << ',' << e.max << ',' << 100 * e.rms / diag[k] << ','
          << 100 * e.max / diag[k] << ',' << m.active_pairs << '\n';
    }
  }
}

struct Run {
  std::vector<MatX3d> dense;  // first object, per frame
  double frame_seconds = 0;
  int nodes = 0, tets = 0;
};

Run run_resolution(Scene scene, int cells, int frames) {
  for (ObjectSpec& o : scene.objects) {
    if (!o.primitive)
      throw InputError("deformation_error: the resolution scene must use primitive objects");
    o.primitive->cells = cells;
  }
  World world = make_world(scene, fs::path(ICD_SOURCE_DIR) / "assets",
              fs::canonical("/proc/self/exe").parent_path());
  Run run;
  run.nodes = static_cast<int>(world.objects()[0].rest.rows());
  run.tets = static_cast<int>(world.objects()[0].asset.coarse.T.rows());
  std::vector<double> wall;
  for (int f = 0; f < frames; ++f) {
    wall.push_back(world.step().wall);
    run.dense.push_back(experiments::dense_positions(world.objects()[0]));
  }
  run.frame_seconds = median(wall);
  return run;
}

int run(int argc, char** argv) {
  fs::path out = "results/deformation_error";
  fs::path scene_path = fs::path(ICD_SOURCE_DIR) / "experiments/scenes/bunny_dragon.json";
  fs::path res_path = fs::path(ICD_SOURCE_DIR) / "experiments/scenes/two_spheres.json";
  std::string cells_text = "2,3,4,6,8";
  int frames = 60, reps = 5, fine = 12;
  std::vector<std::string> overrides;  // --set
  icd::experiments::Cli cli(
      "deformation_error",
      "  Defaults: bunny_dragon.json for the links, two_spheres.json with cells 2,3,4,6,8\n"
      "  against 12 for the resolution; 60 frames.");
  cli.path("--out", out, "DIR", "output folder (default results/deformation_error)")
      .path("--scene", scene_path, "FILE", "scene of the link experiment")
      .integer("--frames", frames, "N", "frames per run", 1)
      .integer("--reps", reps, "N", "repetitions (default 5)", 1)
      .path("--resolution-scene", res_path, "FILE", "scene of the resolution experiment")
      .text("--cells", cells_text, "a,b,...", "coarse resolutions (cells per side)")
      .integer("--fine", fine, "N", "reference resolution (cells per side)", 1);
  cli.scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  const std::vector<double> cells = experiments::parse_list(cells_text, "--cells");
  auto prepare = [&overrides](const fs::path& p) {
    Scene s = load_scene(p, overrides);
    s.output = OutputSpec{};
    s.world.target_fps = 0;
    return s;
  };
  std::ostringstream links;
  links << "scene,frame,object,dense_vertices,coarse_nodes,outside_vertices,links_seconds,"
           "barycentric_seconds,rms_error,max_error,rms_error_pct_bbox,max_error_pct_bbox,active_"
           "pairs\n";
  links_vs_barycentric(prepare(scene_path), frames, reps, links);

  const Scene res_scene = prepare(res_path);
  const Run ref = run_resolution(res_scene, fine, frames);
  const double diag = bbox_diagonal(ref.dense[0]);
  std::ostringstream res;
  res << "scene,cells,coarse_nodes,coarse_tets,frame_seconds,rms_error,max_error,rms_error_pct_"
         "bbox,"
         "max_error_pct_bbox,fine_cells,fine_coarse_tets,fine_frame_seconds\n";
  for (double c : cells) {
    const Run run = run_resolution(res_scene, static_cast<int>(c), frames);
    double rms = 0, mx = 0;
    for (int f = 0; f < frames; ++f) {
      const Error e = compare(run.dense[f], ref.dense[f]);
      rms += e.rms * e.rms / frames;
      mx = std::max(mx, e.max);
    }
    rms = std::sqrt(rms);
    res << res_scene.name << ',' << c << ',' << run.nodes << ',' << run.tets << ','
        << run.frame_seconds << ',' << rms << ',' << mx << ',' << 100 * rms / diag << ','
        << 100 * mx / diag << ',' << fine << ',' << ref.tets << ',' << ref.frame_seconds << '\n';
    std::printf(
        "cells %2g (%5d tets): %.3g ms/frame, RMS error %.3g%% of bbox, max %.3g%% (fine %d: %d "
        "tets, "
        "%.3g ms/frame)\n",
        c, run.tets, 1e3 * run.frame_seconds, 100 * rms / diag, 100 * mx / diag, fine, ref.tets,
        1e3 * ref.frame_seconds);
    std::fflush(stdout);
  }
  fs::create_directories(out);
  write_file_atomically(out / "links.csv", links.str());
  write_file_atomically(out / "resolution.csv", res.str());
  std::printf("results: %s\n", fs::absolute(out).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("deformation_error", run, argc, argv);
}
