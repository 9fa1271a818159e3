// icd-main: the project's main job (README command 1): the default
// bunny-dragon scene of the paper (experiments/scenes/bunny_dragon.json),
// preprocessing the real meshes on first use.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "experiments/runner/run.hpp"
#include "icd/config.hpp"

namespace {

void usage() {
  std::printf(
      "usage: icd-main [--out DIR] [--scene FILE] [--frames N]\n"
      "  --out DIR     results folder (default: results/main)\n"
      "  --scene FILE  scene to run (default: %s/experiments/scenes/bunny_dragon.json)\n"
      "  --frames N    override the scene's frame count\n",
      ICD_SOURCE_DIR);
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = "results/main";
  std::filesystem::path scene_path =
      std::filesystem::path(ICD_SOURCE_DIR) / "experiments/scenes/bunny_dragon.json";
  int frames = -1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (a == "--scene" && i + 1 < argc) {
      scene_path = argv[++i];
    } else if (a == "--frames" && i + 1 < argc) {
      try {
        frames = std::stoi(argv[++i]);
      } catch (const std::exception&) {
        frames = -2;
      }
      if (frames < 0) {
        std::fprintf(stderr, "icd-main: --frames: expected a non-negative integer\n");
        return 2;
      }
    } else if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else {
      std::fprintf(stderr, "icd-main: unknown argument '%s'\n", a.c_str());
      usage();
      return 2;
    }
  }
  try {
    const icd::runner::Scene scene = icd::runner::load_scene(scene_path);
    std::printf("scene \"%s\" (%s)\n", scene.name.c_str(), scene_path.c_str());
    for (const std::string& line : icd::runner::make_plan(scene).describe(scene))
      std::printf("  %s\n", line.c_str());
    icd::runner::RunOptions opt;
    opt.out_dir = out;
    opt.cache_dir = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
    opt.tool_dir = std::filesystem::canonical("/proc/self/exe").parent_path();
    opt.frames = frames;
    icd::runner::run_scene(scene, opt);
    std::printf("results: %s (frames.csv; vtu/*.pvd for ParaView)\n",
                std::filesystem::absolute(out).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "icd-main: %s\n", e.what());
    return 1;
  }
  return 0;
}
