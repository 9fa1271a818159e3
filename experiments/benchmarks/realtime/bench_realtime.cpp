// Real-time frames, side by side in one run: each scene runs as two Worlds
// stepped in turn frame by frame (1 thread: the previous code path; 2
// threads), then once in real-time mode at 60 Hz on 2 threads. Prints per
// frame medians of wall and CPU time, the real-time factor by wall clock,
// the speed-up, the share of frames that met the 60 Hz deadline, what the
// FEM costs per sub-step, and the load (/proc/loadavg) before and after.
//
// usage: bench_realtime [--frames N] [SCENE.json ...]
//   default scenes: experiments/scenes/bunny_dragon.json (the main job) and
//   experiments/scenes/many_objects.json; default 120 frames each.
#include "experiments/common/cli.hpp"
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <icd/config.hpp>
#include <icd/mesh/core/error.hpp>
#include "experiments/runner/run.hpp"
#include "experiments/runner/scene.hpp"

namespace {

using icd::coupling::FrameMetrics;
using icd::coupling::World;

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string loadavg() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

struct Series {
  std::vector<double> wall, cpu, fem, substeps;
  double total_wall = 0;
  void add(const FrameMetrics& m, double wall_s, double cpu_s) {
    wall.push_back(wall_s);
    cpu.push_back(cpu_s);
    fem.push_back(m.times.fem);
    substeps.push_back(m.substeps);
    total_wall += wall_s;
  }
};

FrameMetrics timed_step(World& w, Series& s) {
  const double c0 = cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  const FrameMetrics m = w.step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.add(m, wall, cpu_seconds() - c0);
  return m;
}

void run_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides, int frames,
               const std::filesystem::path& tools) {
  icd::runner::Scene scene = icd::runner::load_scene(path, overrides);
  const std::filesystem::path cache = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
  const double dt = 1.0 / scene.world.frame_rate;
  std::printf("\n== %s: %zu objects, %d frames of %.2f ms simulated, load before %s\n",
              scene.name.c_str(), scene.objects.size(), frames, 1e3 * dt, loadavg().c_str());
  std::fflush(stdout);
  scene.world.target_fps = 0;
  scene.world.threads = 1;
  World one = icd::runner::make_world(scene, cache, tools);
  scene.world.threads = 2;
  World two = icd::runner::make_world(scene, cache, tools);
  Series s1, s2;
  for (int f = 0; f < frames; ++f) {  // interleaved, alternating which goes first
    if (f % 2 == 0) {
      timed_step(one, s1);
      timed_step(two, s2);
    } else {
      timed_step(two, s2);
      timed_step(one, s1);
    }
  }
  scene.world.target_fps = 60;
  World rt = icd::runner::make_world(scene, cache, tools);
  Series s3;
  int met = 0, fem_over = 0, floored = 0;
  double worst = 0;
  std::string warning;
  for (int f = 0; f < frames; ++f) {
    const FrameMetrics m = timed_step(rt, s3);
    met += m.deadline_met == 1;
    fem_over += m.fem_over_deadline;
    floored += m.min_budget_queries;
    worst = std::max(worst, m.lateness);
    if (!m.deadline_warning.empty()) warning = m.deadline_warning;
  }
  const double sim = frames * dt;
  std::printf("%-22s %12s %12s %10s %10s %14s %12s\n", "", "wall ms/fr", "CPU ms/fr", "x real",
              "FEM ms/fr", "sub-steps/fr", "us/sub-step");
  const auto row = [&](const char* label, const Series& s) {
    const double sub = median(s.substeps);
    std::printf("%-22s %12.2f %12.2f %10.2f %10.2f %14.0f %12.1f\n", label, 1e3 * median(s.wall),
                1e3 * median(s.cpu), sim / s.total_wall, 1e3 * median(s.fem), sub,
                sub > 0 ? 1e6 * median(s.fem) / sub : 0.0);
  };
  row("1 thread (old path)", s1);
  row("2 threads", s2);
  row("2 threads, 60 Hz RT", s3);
  std::printf("speed-up 2 vs 1 thread (median wall per frame): %.2fx\n",
              median(s1.wall) / median(s2.wall));
  std::printf("real-time mode at 60 Hz: %d of %d frames met the deadline (%.1f%%), worst lateness "
              "%.2f ms, FEM alone over the deadline in %d frames, %d queries at the minimum budget\n",
              met, frames, 100.0 * met / frames, 1e3 * worst, fem_over, floored);
  if (!warning.empty()) std::printf("  %s\n", warning.c_str());
  std::printf("load after %s\n", loadavg().c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 120;
  std::vector<std::filesystem::path> scenes;
  std::vector<std::string> overrides;
  icd::experiments::Cli cli(
      "bench_realtime",
      "  Each scene stepped with 1 thread (the previous path) and 2 threads, interleaved frame by\n"
      "  frame, then in real-time mode at 60 Hz; wall and CPU time per frame (medians).\n"
      "  Default scenes: experiments/scenes/bunny_dragon.json and many_objects.json.");
  cli.arguments("SCENE", scenes, "scene files (JSON)", false)
      .integer("--frames", frames, "N", "frames per configuration (default 120)", 1, 100000)
      .scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  if (scenes.empty()) {
    const std::filesystem::path root(ICD_SOURCE_DIR);
    scenes = {root / "experiments/scenes/bunny_dragon.json",
              root / "experiments/scenes/many_objects.json"};
  }
  const std::filesystem::path tools =
      std::filesystem::absolute(std::filesystem::path(argv[0])).parent_path();
  std::printf("bench_realtime: %u hardware threads; load %s\n",
              std::max(1u, static_cast<unsigned>(std::thread::hardware_concurrency())),
              loadavg().c_str());
  try {
    for (const auto& s : scenes) run_scene(s, overrides, frames, tools);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_realtime: %s\n", e.what());
    return 1;
  }
  return 0;
}
