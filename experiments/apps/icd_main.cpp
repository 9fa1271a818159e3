// icd-main: the project's main job (README command 1): the default
// bunny-dragon scene of the paper (experiments/scenes/bunny_dragon.json),
// preprocessing the real meshes on first use.
#include <vector>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/runner/locations.hpp"
#include "experiments/runner/run.hpp"

namespace {

int run(int argc, char** argv) {
  std::filesystem::path out = "results/main";
  std::filesystem::path scene_path = icd::runner::scenes_dir() / "bunny_dragon.json";
  std::filesystem::path cache_dir = icd::runner::default_cache_dir();
  int frames = -1, threads = -1;
  std::vector<std::string> overrides;  // --set
  icd::experiments::Cli cli("icd-main",
                                    "  The project's main job: the paper's bunny-dragon scene.");
  cli.path("--out", out, "DIR", "results folder (default: results/main)")
      .path("--scene", scene_path, "FILE",
            "scene to run (default: " + scene_path.string() + ")")
      .path("--cache-dir", cache_dir, "DIR",
            "asset cache folder (default: " + cache_dir.string() + ", see README Programs)")
      .integer("--frames", frames, "N", "override the scene's frame count", 1, 100000000)
      .integer("--threads", threads, "N",
               "worker threads advancing the objects (0 = hardware concurrency; overrides the "
               "scene's threads field)",
               0, 1024);
  cli.scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  // --threads is the scene field `threads`, applied after every --set.
  if (threads >= 0) overrides.push_back("threads=" + std::to_string(threads));
  const icd::runner::Scene scene = icd::runner::load_scene(scene_path, overrides);
  std::printf("scene \"%s\" (%s)\n", scene.name.c_str(), scene_path.c_str());
  for (const std::string& line : icd::runner::describe_plan(scene))
    std::printf("  %s\n", line.c_str());
  icd::runner::RunOptions opt;
  opt.out_dir = out;
  opt.cache_dir = cache_dir;
  opt.tool_dir = icd::runner::program_dir();
  opt.frames = frames;
  opt.scene_file = scene_path;
  icd::runner::run_scene(scene, opt);
  std::printf("results: %s (frames.csv, scene.json, version.txt; vtu/run.pvd for ParaView)\n",
              std::filesystem::absolute(out).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("icd-main", run, argc, argv);
}
