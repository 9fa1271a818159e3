// icd-run: runs a scene file (see experiments/scenes/ and README); icd-run --help.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/runner/locations.hpp"
#include "experiments/runner/run.hpp"

namespace {

int run(int argc, char** argv) {
  std::filesystem::path scene_path, out, cache_dir = icd::runner::default_cache_dir();
  int frames = -1, threads = -1;
  double target_fps = -1;
  bool dry = false, quiet = false;
  std::vector<std::string> overrides;
  icd::experiments::Cli cli(
      "icd-run",
      "  Runs a scene file (experiments/scenes/, installed under share/icd/scenes).\n"
      "  Asset cache: --cache-dir, else $ICD_CACHE_DIR, else the source tree's assets/ for a\n"
      "  program in the build tree and $XDG_CACHE_HOME/icd (~/.cache/icd) for an installed one.\n"
      "  Relative mesh paths: the scene's folder, the working folder, $ICD_DATA_DIR.");
  cli.argument("SCENE", scene_path, "scene file (JSON)", true)
      .path("--out", out, "DIR", "results folder (default: results/<scene name as a file name>)")
      .integer("--frames", frames, "N", "override the scene's frame count", 1, 100000000)
      .real("--target-fps", target_fps, "F",
            "real-time mode at F frames per second (0 = off; overrides the scene)", 0.0, 1e5)
      .integer("--threads", threads, "N",
               "worker threads advancing the objects (0 = hardware concurrency; overrides the "
               "scene's threads field)",
               0, 1024)
      .path("--cache-dir", cache_dir, "DIR", "asset cache folder (see below)")
      .custom("--set", "KEY=VALUE",
              "override a scene field (repeatable; KEY dotted, array indices as numbers, e.g. "
              "objects.1.material.young=2e5; VALUE JSON, else a string)",
              [&](const std::string& v) { overrides.push_back(v); })
      .flag("--dry-run", dry, "print the stages the scene needs and check its input files, run nothing")
      .flag("--quiet", quiet, "no progress bar");
  if (const auto status = cli.parse(argc, argv)) return *status;
  // --threads is the scene field `threads`, applied after every --set.
  if (threads >= 0) overrides.push_back("threads=" + std::to_string(threads));
  const icd::runner::Scene scene = icd::runner::load_scene(scene_path, overrides);
  std::printf("scene \"%s\": %zu objects, %d frames at %g Hz\n", scene.name.c_str(),
              scene.objects.size(), frames >= 0 ? frames : scene.frames, scene.world.frame_rate);
  for (const std::string& line : icd::runner::describe_plan(scene))
    std::printf("  %s\n", line.c_str());
  const double fps = target_fps >= 0 ? target_fps : scene.world.target_fps;
  if (fps > 0)
    std::printf(
        "  real-time mode: %g frames per second; collision detection gets what is left of each "
        "frame\n",
        fps);
  if (dry) {
    icd::runner::check_scene_inputs(scene);
    std::printf("  input files: all present and within their size limits\n");
    return 0;
  }
  icd::runner::RunOptions opt;
  // The scene's name is a label: results/<name as one file name>, never a path.
  opt.out_dir = out.empty()
                    ? std::filesystem::path("results") / icd::runner::file_name_from(scene.name)
                    : std::filesystem::path(out);
  opt.cache_dir = cache_dir;
  opt.tool_dir = icd::runner::program_dir();
  opt.frames = frames;
  opt.scene_file = scene_path;
  opt.target_fps = target_fps;
  opt.progress = !quiet;
  icd::runner::run_scene(scene, opt);
  std::printf("results: %s\n", std::filesystem::absolute(opt.out_dir).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("icd-run", run, argc, argv);
}
