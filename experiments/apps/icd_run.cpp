// icd-run: runs a scene file (see experiments/scenes/ and README).
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <icd/config.hpp>
#include <icd/mesh/core/input_file.hpp>
#include "experiments/runner/run.hpp"

namespace {

void usage() {
  std::printf(
      "usage: icd-run SCENE.json [--out DIR] [--frames N] [--target-fps F] [--set KEY=VALUE]...\n"
      "               [--dry-run] [--quiet]\n"
      "  --out DIR    results folder (default: results/<scene name as a file name>)\n"
      "  --frames N   override the scene's frame count (1 to 100000000)\n"
      "  --target-fps F  real-time mode at F frames per second (0 = off; overrides the scene)\n"
      "  --set KEY=VALUE  override a scene field (repeatable; KEY dotted, array indices as\n"
      "               numbers, e.g. objects.1.material.young=2e5; VALUE JSON, else a string)\n"
      "  --dry-run    print the stages the scene needs and check its input files, run nothing\n"
      "  --quiet      no progress bar\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_path, out;
  int frames = -1;
  double target_fps = -1;
  bool dry = false, quiet = false;
  std::vector<std::string> overrides;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (a == "--frames" && i + 1 < argc) {
      char* end = nullptr;
      const long v = std::strtol(argv[++i], &end, 10);
      if (end == argv[i] || *end != '\0' || v < 1 || v > 100000000) {  // as the scene's "frames"
        std::fprintf(stderr, "icd-run: --frames: must be in [1, 100000000], got '%s'\n",
                     icd::escape_bytes(argv[i]).c_str());
        return 2;
      }
      frames = static_cast<int>(v);
    } else if (a == "--target-fps" && i + 1 < argc) {
      char* end = nullptr;
      target_fps = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(target_fps >= 0 && target_fps <= 1e5)) {
        std::fprintf(stderr, "icd-run: --target-fps: expected a number in [0, 1e5], got '%s'\n",
                     icd::escape_bytes(argv[i]).c_str());
        return 2;
      }
    } else if (a == "--set" && i + 1 < argc) {
      overrides.push_back(argv[++i]);
    } else if (a == "--dry-run") {
      dry = true;
    } else if (a == "--quiet") {
      quiet = true;
    } else if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else if (scene_path.empty() && !a.empty() && a[0] != '-') {
      scene_path = a;
    } else {
      std::fprintf(stderr, "icd-run: unknown argument '%s'\n", icd::escape_bytes(a).c_str());
      usage();
      return 2;
    }
  }
  if (scene_path.empty()) {
    usage();
    return 2;
  }
  try {
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
    opt.cache_dir = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
    opt.tool_dir = std::filesystem::canonical("/proc/self/exe").parent_path();
    opt.frames = frames;
    opt.target_fps = target_fps;
    opt.progress = !quiet;
    icd::runner::run_scene(scene, opt);
    std::printf("results: %s\n", std::filesystem::absolute(opt.out_dir).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "icd-run: %s\n", e.what());
    return 1;
  }
  return 0;
}
