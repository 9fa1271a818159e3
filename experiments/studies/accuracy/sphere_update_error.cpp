// sphere_update_error: how well the per-frame sphere update (paper 4.4) keeps
// covering the deformed dense surface, how tight it stays, and what it costs,
// against a tree rebuilt from scratch on the deformed surface (octree builder,
// same depth). A scene is run (collision budget of the scene); at every frame
// and for every deformable object:
//   - updated trees (PaperRatio and DisplacementBound modes, no margin), from
//     the rest tree and the current coarse nodes: update time (median of
//     --reps), leaf coverage of the deformed dense vertices (fraction outside
//     every leaf sphere, largest gap, m), tightness = total leaf-sphere volume
//     / volume enclosed by the deformed dense surface;
//   - the rebuilt tree: build time, coverage, tightness.
// Writes sphere_update.csv into --out (one row per frame, object and method).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <icd/collision/coverage.hpp>
#include <icd/collision/octree_tree.hpp>
#include <icd/collision/sphere_update.hpp>
#include <icd/config.hpp>
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

// Volume enclosed by a closed, outward-oriented triangle mesh (divergence theorem).
double enclosed_volume(const MatX3d& V, const MatX3i& F) {
  double v = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    v += V.row(F(f, 0)).dot(V.row(F(f, 1)).cross(V.row(F(f, 2)))) / 6.0;
  return std::abs(v);
}

double leaf_volume(const collision::SphereTree& t) {
  double v = 0;
  for (int i = 0; i < t.num_nodes(); ++i)
    if (t.is_leaf(i)) v += 4.0 / 3.0 * std::numbers::pi * std::pow(t.spheres[i].r, 3);
  return v;
}

int run(int argc, char** argv) {
  fs::path out = "results/sphere_update";
  fs::path scene_path = fs::path(ICD_SOURCE_DIR) / "experiments/scenes/two_spheres.json";
  int frames = 60, every = 1, reps = 5;
  std::vector<std::string> overrides;  // --set
  icd::experiments::Cli cli(
      "sphere_update_error",
      "  Default scene experiments/scenes/two_spheres.json (octree trees, so the rebuilt tree\n"
      "  uses the same builder), 60 frames, every frame.");
  cli.path("--out", out, "DIR", "output folder (default results/sphere_update)")
      .path("--scene", scene_path, "FILE", "scene file")
      .integer("--frames", frames, "N", "frames", 1)
      .integer("--every", every, "N", "compare every N-th frame", 1)
      .integer("--reps", reps, "N", "timing repetitions (default 5)", 1);
  cli.scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  std::ostringstream csv;
  csv << "scene,frame,object,method,seconds,uncovered_fraction,max_gap,tightness,leaf_spheres,"
         "max_displacement\n";
  Scene scene = load_scene(scene_path, overrides);
  scene.output = OutputSpec{};
  scene.world.target_fps = 0;
  World world = make_world(scene, fs::path(ICD_SOURCE_DIR) / "assets",
                           fs::canonical("/proc/self/exe").parent_path());
  for (int f = 0; f < frames; ++f) {
    world.step();
    if (f % every) continue;
    for (const RuntimeObject& o : world.objects()) {
      if (!o.sim) continue;
      const MatX3d dense = experiments::dense_positions(o);
      const MatX3i& F = o.asset.dense.F;
      const double volume = enclosed_volume(dense, F);
      // Displacement relative to the rigid motion is what the update must follow;
      // report the largest node displacement from rest minus the mean (deformation + rotation).
      const MatX3d u = o.positions - o.rest;
      const double max_disp = (u.rowwise() - u.colwise().mean()).rowwise().norm().maxCoeff();
      auto row = [&](const char* method, double secs, const collision::SphereTree& t) {
        const collision::CoverageReport cov = collision::measure_coverage(t, dense, -1);
        int leaves = 0;
        for (int i = 0; i < t.num_nodes(); ++i) leaves += t.is_leaf(i);
        csv << scene.name << ',' << f << ',' << o.setup.name << ',' << method << ',' << secs << ','
            << cov.uncovered_fraction << ',' << cov.max_gap << ',' << leaf_volume(t) / volume << ','
            << leaves << ',' << max_disp << '\n';
      };
      for (const auto& [name, mode] :
           {std::pair{"update_paper_ratio", collision::SphereUpdateMode::PaperRatio},
            std::pair{"update_displacement_bound",
                      collision::SphereUpdateMode::DisplacementBound}}) {
        collision::SphereTree t = o.asset.spheres;
        collision::SphereUpdateOptions opt;
        opt.mode = mode;
        std::vector<double> ts;
        for (int r = 0; r < reps; ++r) {
          const auto t0 = std::chrono::steady_clock::now();
          collision::update_spheres(t, o.rest, o.positions, opt);
          ts.push_back(seconds_since(t0));
        }
        row(name, median(ts), t);
      }
      collision::OctreeTreeOptions oo;
      oo.levels = o.asset.spheres.num_levels();
      collision::SphereTree rebuilt;
      std::vector<double> ts;
      for (int r = 0; r < std::min(reps, 3); ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        rebuilt = collision::build_octree_tree(dense, F, oo);
        ts.push_back(seconds_since(t0));
      }
      row("rebuild_octree", median(ts), rebuilt);
    }
  }
  fs::create_directories(out);
  write_file_atomically(out / "sphere_update.csv", csv.str());
  std::printf("results: %s\n", fs::absolute(out / "sphere_update.csv").c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("sphere_update_error", run, argc, argv);
}
