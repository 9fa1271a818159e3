// fig9: the paper's Fig. 9. For each critical time, a fresh run of the scene
// from identical initial conditions is taken to the same frame: `--after`
// frames past first contact in the uninterrupted run; there we write the dense
// meshes and the spheres used for the contact response (COLLISIONLIST leaves
// and untested PAIRLIST pairs) as VTU files, and a manifest.csv for
// scripts/plot_fig9.py, which renders one panel per critical time.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <icd/config.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/atomic_write.hpp>
#include <icd/mesh/io/vtk_writer.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/runner/run.hpp"
#include "experiments/studies/paper/contact_moment.hpp"

namespace fs = std::filesystem;
using namespace icd;
using namespace icd::runner;

namespace {
int run(int argc, char** argv) {
  fs::path out = "results/fig9";
  fs::path scene_path = fs::path(ICD_SOURCE_DIR) / "experiments/scenes/bunny_dragon.json";
  std::string budgets_text = "1e-4,1e-3,1e-2,1e-1";
  int max_frames = 200, after = 3;
  std::vector<std::string> overrides;  // --set
  icd::experiments::Cli cli(
      "fig9",
      "  Default: experiments/scenes/bunny_dragon.json, critical times 1e-4,1e-3,1e-2,1e-1 s,\n"
      "  3 frames after first contact (uninterrupted run). Writes DIR/budget_<t>/*.vtu and\n"
      "  DIR/manifest.csv.");
  cli.path("--out", out, "DIR", "output folder (default results/fig9)")
      .path("--scene", scene_path, "FILE", "scene file")
      .text("--budgets", budgets_text, "a,b,...", "critical times (s)")
      .integer("--max-frames", max_frames, "N", "frames searched for contact (default 200)", 1)
      .integer("--after", after, "N", "frames after first contact (default 3)", 0);
  cli.scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  const fs::path cache = fs::path(ICD_SOURCE_DIR) / "assets";
  const fs::path tools = fs::canonical("/proc/self/exe").parent_path();
  std::ostringstream manifest;
  manifest << "budget,dir,scene,contact_frame,frame,pair_list,collision_list,tests,completed_level,"
              "objects,spheres,failure\n";
  const std::vector<double> budgets = experiments::parse_list(budgets_text, "--budgets");
  Scene scene = load_scene(scene_path, overrides);
  scene.output = OutputSpec{};
  scene.world.target_fps = 0;
  scene.world.collision.query.budget_tests = -1;
  fs::create_directories(out);
  // The moment: `after` frames past first contact in the run with the
  // largest budget, the same frame index for every budget (a coarse answer
  // reports contact earlier, so per-run contact frames would differ).
  int frame = -1;
  {
    scene.world.collision.query.budget_seconds = *std::max_element(budgets.begin(), budgets.end());
    World reference = make_world(scene, cache, tools);
    if (reference.plan().pairs.empty())
      throw InputError(scene_path.string() + ": no collision pair");
    int contact = -1;
    try {
      for (int f = 0; f < max_frames && (contact < 0 || f <= contact + after); ++f) {
        if (reference.step().active_pairs > 0 && contact < 0) contact = f;
        frame = f;
      }
    } catch (const std::exception& e) {
      // A simulation that fails after contact: draw its last completed frame.
      if (contact < 0) throw;
      std::fprintf(stderr, "fig9: reference run failed after frame %d (drawing that frame): %s\n",
                   frame, e.what());
    }
    if (contact < 0)
      throw InputError(scene_path.string() + ": no contact within " + std::to_string(max_frames) +
                       " frames");
  }
  for (double budget : budgets) {
    scene.world.collision.query.budget_seconds = budget;
    World world = make_world(scene, cache, tools);
    experiments::ContactMoment cm;
    std::string failure;
    try {
      for (int f = 0; f <= frame; ++f) {
        cm.frames.push_back(world.step());
        if (cm.contact_frame < 0 && cm.frames.back().active_pairs > 0) cm.contact_frame = f;
        cm.last_frame = f;
      }
    } catch (const std::exception& e) {
      // Drawn anyway (the last completed frame), with the failure in the manifest.
      failure = e.what();
      std::replace(failure.begin(), failure.end(), ',', ';');
      std::replace(failure.begin(), failure.end(), '\n', ' ');
      std::fprintf(stderr, "fig9: budget %g s: %s\n", budget, e.what());
      if (cm.frames.empty()) throw;
    }
    char dir[64];
    std::snprintf(dir, sizeof dir, "budget_%g", budget);
    fs::create_directories(out / dir);
    std::string objects, spheres;
    for (RuntimeObject& o : world.objects()) {
      const std::string name = runner::file_name_from(o.setup.name) + "_dense.vtu";
      write_vtu_surface_mesh(out / dir / name,
                             SurfaceMesh{experiments::dense_positions(o), o.asset.dense.F});
      objects += (objects.empty() ? "" : ";") + name;
    }
    // The first pair only (the paper's scenes have one).
    for (int side = 0; side < 2; ++side) {
      const auto [i, j] = world.plan().pairs[0];
      const std::string name =
          runner::file_name_from(world.objects()[side ? j : i].setup.name) + "_contact_spheres.vtu";
      write_contact_spheres(world, 0, side, out / dir / name);
      spheres += (spheres.empty() ? "" : ";") + name;
    }
    const FrameMetrics& m = cm.frames.back();
    manifest << budget << ',' << dir << ',' << scene.name << ',' << cm.contact_frame << ','
             << cm.last_frame << ',' << m.pair_list << ',' << m.collision_list << ',' << m.tests
             << ',' << m.completed_level << ',' << objects << ',' << spheres << ',' << failure
             << '\n';
    std::printf(
        "%-14s budget %-7g contact frame %3d, drawn frame %3d: PAIRLIST %lld COLLISIONLIST "
        "%lld\n",
        scene.name.c_str(), budget, cm.contact_frame, cm.last_frame,
        static_cast<long long>(m.pair_list), static_cast<long long>(m.collision_list));
    std::fflush(stdout);
  }
  write_file_atomically(out / "manifest.csv", manifest.str());
  std::printf("results: %s\n", fs::absolute(out).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return icd::experiments::guarded_main("fig9", run, argc, argv); }
