// Real-time frames, side by side in one run: each scene runs as two Worlds
// stepped in turn frame by frame (1 thread: the previous code path; 2
// threads), then once in real-time mode at 60 Hz on 2 threads. Prints per
// frame medians of wall and CPU time (and the most FEM sub-steps of a frame), the real-time factor by wall clock,
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
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <icd/collision/traversal.hpp>
#include <icd/config.hpp>
#include <icd/coupling/contact_response.hpp>
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
  for (const std::string& line : icd::runner::describe_mass_scaling(one))
    std::printf("%s\n", line.c_str());
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
  std::printf("%-22s %12s %12s %10s %10s %14s %12s %12s\n", "", "wall ms/fr", "CPU ms/fr", "x real",
              "FEM ms/fr", "sub-steps/fr", "us/sub-step", "max sub/fr");
  const auto row = [&](const char* label, const Series& s) {
    const double sub = median(s.substeps);
    std::printf("%-22s %12.2f %12.2f %10.2f %10.2f %14.0f %12.1f %12.0f\n", label, 1e3 * median(s.wall),
                1e3 * median(s.cpu), sim / s.total_wall, 1e3 * median(s.fem), sub,
                sub > 0 ? 1e6 * median(s.fem) / sub : 0.0,
                *std::max_element(s.substeps.begin(), s.substeps.end()));
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

// Level of detail for many pairs (--lod): the scene with its own query
// budget, shared among the pairs evenly and by priority (two runs). After
// every frame each pair's last query is compared with an unlimited query on
// the same spheres (the oracle): the penalty force (Eq. 11, the paper's
// response to the query as it stands) of each pair with a contact, relative
// error |F - F_exact| / |F_exact|, and the collision time per frame.
void run_lod(const std::filesystem::path& path, const std::vector<std::string>& overrides,
             int frames, const std::filesystem::path& tools) {
  icd::runner::Scene scene = icd::runner::load_scene(path, overrides);
  const std::filesystem::path cache = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
  std::printf("\n== %s, level of detail: %d frames, budget %g s / %lld tests per query, load %s\n",
              scene.name.c_str(), frames, scene.world.collision.query.budget_seconds,
              static_cast<long long>(scene.world.collision.query.budget_tests), loadavg().c_str());
  std::printf("%-10s %8s %12s %12s %12s %12s %12s %10s\n", "split", "samples", "median err",
              "p90 err", "max err", "collision ms", "wall ms/fr", "interrupt");
  for (const icd::coupling::BudgetSplit split :
       {icd::coupling::BudgetSplit::Even, icd::coupling::BudgetSplit::Priority}) {
    scene.world.collision.budget_split = split;
    scene.world.target_fps = 0;
    World w = icd::runner::make_world(scene, cache, tools);
    std::vector<double> err, coll, wall;
    int interrupted = 0;
    icd::collision::CollisionRequest exact = scene.world.collision.query;
    exact.budget_seconds = std::numeric_limits<double>::infinity();
    exact.budget_tests = -1;
    exact.start_front = nullptr;
    exact.record_front = false;
    icd::collision::CollisionResult oracle;
    for (int f = 0; f < frames; ++f) {
      const auto t0 = std::chrono::steady_clock::now();
      const FrameMetrics m = w.step();
      wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      coll.push_back(m.times.collision);
      interrupted += m.interrupted;
      const auto& pairs = w.plan().pairs;
      for (size_t p = 0; p < pairs.size(); ++p) {
        const auto& a = w.objects()[pairs[p].first];
        const auto& b = w.objects()[pairs[p].second];
        icd::collision::collide(a.asset.spheres, b.asset.spheres, exact, oracle);
        icd::coupling::ContactOptions co = scene.world.collision.contact;
        icd::MatX3d fa = icd::MatX3d::Zero(a.positions.rows(), 3), fb = icd::MatX3d::Zero(b.positions.rows(), 3);
        const Eigen::Vector3d truth = icd::coupling::apply_contact_forces(
            a.asset.spheres, b.asset.spheres, oracle, co, fa, fb).total_force_a;
        if (truth.norm() == 0) continue;
        fa.setZero();
        fb.setZero();
        const Eigen::Vector3d got = icd::coupling::apply_contact_forces(
            a.asset.spheres, b.asset.spheres, w.results()[p], co, fa, fb).total_force_a;
        err.push_back((got - truth).norm() / truth.norm());
      }
    }
    std::vector<double> sorted = err;
    std::sort(sorted.begin(), sorted.end());
    const double p90 = sorted.empty() ? 0 : sorted[static_cast<size_t>(0.9 * (sorted.size() - 1))];
    std::printf("%-10s %8zu %12.3f %12.3f %12.3f %12.3f %12.2f %10d\n",
                split == icd::coupling::BudgetSplit::Even ? "even" : "priority", err.size(),
                median(err), p90, sorted.empty() ? 0 : sorted.back(), 1e3 * median(coll),
                1e3 * median(wall), interrupted);
    std::fflush(stdout);
  }
  std::printf("load after %s\n", loadavg().c_str());
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 120;
  bool lod = false;
  std::vector<std::filesystem::path> scenes;
  std::vector<std::string> overrides;
  icd::experiments::Cli cli(
      "bench_realtime",
      "  Each scene stepped with 1 thread (the previous path) and 2 threads, interleaved frame by\n"
      "  frame, then in real-time mode at 60 Hz; wall and CPU time per frame (medians).\n"
      "  Default scenes: experiments/scenes/bunny_dragon.json and many_objects.json.");
  cli.arguments("SCENE", scenes, "scene files (JSON)", false)
      .integer("--frames", frames, "N", "frames per configuration (default 120)", 1, 100000)
      .flag("--lod", lod,
            "level of detail for many pairs instead: the scene's query budget shared evenly and "
            "by priority, per-pair contact force error against an unlimited query of the same "
            "spheres, and collision time")
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
    for (const auto& s : scenes)
      lod ? run_lod(s, overrides, frames, tools) : run_scene(s, overrides, frames, tools);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_realtime: %s\n", e.what());
    return 1;
  }
  return 0;
}
