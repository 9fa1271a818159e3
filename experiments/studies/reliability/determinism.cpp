// determinism: runs the same scene several times and checks that everything
// but wall-clock times is bitwise identical (issue 9). The budget is counted
// in sphere tests (wall-clock budgets are machine dependent).
//  1. run_scene twice into two folders: frames.csv identical after dropping
//     the wall-time columns, every VTU/PVD file byte-identical;
//  2. the World loop with 1 and with 2 FEM threads (ElasticForces threads):
//     per frame, the CSV row without wall times and every object's coarse
//     (and dense) positions identical bit for bit.
// usage: determinism [--scene FILE] [--frames N=60] [--budget-tests B=2000]
//                    [--vtu-every K=10] [--out DIR]
// Without --scene the two-sphere scene of experiments/scenes is used.
// Exit status 0 when identical, 1 with the first difference otherwise.
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <icd/config.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/runner/run.hpp"
#include "experiments/studies/reliability/soak_scene.hpp"

namespace {

namespace fs = std::filesystem;
using namespace icd;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The columns of frames.csv that hold wall-clock times.
const std::set<std::string> kWallColumns = {"wall",          "fem",       "links",
                                            "sphere_update", "collision", "response"};

// frames.csv without its wall-time columns.
std::string strip_wall_columns(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, out;
  std::vector<bool> keep;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ls(line);
    std::string c;
    while (std::getline(ls, c, ',')) cells.push_back(c);
    if (keep.empty())
      for (const std::string& name : cells) keep.push_back(kWallColumns.count(name) == 0);
    for (size_t i = 0; i < cells.size(); ++i)
      if (i >= keep.size() || keep[i]) out += cells[i] + ',';
    out += '\n';
  }
  return out;
}

// Compares two run folders; returns the first difference or "".
std::string compare_runs(const fs::path& a, const fs::path& b, int& files) {
  const std::string ca = slurp(a / "frames.csv"), cb = slurp(b / "frames.csv");
  if (ca.empty()) return "no frames.csv in " + a.string();
  if (strip_wall_columns(ca) != strip_wall_columns(cb)) return "frames.csv differs";
  files = 1;
  if (!fs::exists(a / "vtu")) return "";
  for (const auto& e : fs::directory_iterator(a / "vtu")) {
    const fs::path other = b / "vtu" / e.path().filename();
    if (!fs::exists(other)) return "missing " + other.string();
    if (slurp(e.path()) != slurp(other)) return e.path().filename().string() + " differs";
    ++files;
  }
  return "";
}

// One World run; returns per frame the CSV row (no wall times) and the raw
// bytes of every object's positions.
std::vector<std::string> world_trace(const runner::Scene& scene, int threads, int& contact_frames) {
  runner::World world = runner::make_world(scene, fs::path(ICD_SOURCE_DIR) / "assets", ICD_TOOL_DIR);
  for (runner::RuntimeObject& o : world.objects())
    if (o.sim) o.sim->model().elastic().set_num_threads(threads);
  std::vector<std::string> trace;
  for (int f = 0; f < scene.frames; ++f) {
    const runner::FrameMetrics m = world.step();
    contact_frames += m.active_pairs > 0;
    std::string t = strip_wall_columns(runner::metrics_csv({m}));
    for (runner::RuntimeObject& o : world.objects()) {
      t.append(reinterpret_cast<const char*>(o.positions.data()),
               sizeof(double) * static_cast<size_t>(o.positions.size()));
      t.append(reinterpret_cast<const char*>(o.dense.data()),
               sizeof(double) * static_cast<size_t>(o.dense.size()));
    }
    trace.push_back(std::move(t));
  }
  return trace;
}

int run(int argc, char** argv) {
  std::string scene_path = std::string(ICD_SOURCE_DIR) + "/experiments/scenes/two_spheres.json";
  int frames = 60, vtu_every = 10;
  long long budget = 2000;
  fs::path out = fs::temp_directory_path() / "icd_determinism";
  std::vector<std::string> overrides;  // --set
  icd::experiments::Cli cli(
      "determinism", "  Two runs of the scene compared file by file, then 1 and 2 FEM threads.");
  cli.text("--scene", scene_path, "FILE", "scene (default two_spheres.json)")
      .integer("--frames", frames, "N", "frames (default 60)", 1)
      .integer("--budget-tests", budget, "B", "sphere tests per query, -1: none (default 2000)",
               -1LL)
      .integer("--vtu-every", vtu_every, "K", "VTU output every K frames (default 10)", 0)
      .path("--out", out, "DIR", "scratch folder");
  cli.scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  runner::Scene scene = runner::load_scene(scene_path, overrides);
  reliability::use_test_budget(scene, budget);
  scene.frames = frames;
  scene.output.csv = true;
  scene.output.vtu_every = vtu_every;

  bool ok = true;
  runner::RunOptions ro;
  ro.cache_dir = fs::path(ICD_SOURCE_DIR) / "assets";
  ro.tool_dir = ICD_TOOL_DIR;
  ro.progress = false;
  ro.log = nullptr;
  fs::remove_all(out);
  for (const char* run : {"run1", "run2"}) {
    ro.out_dir = out / run;
    runner::run_scene(scene, ro);
  }
  int files = 0;
  const std::string diff = compare_runs(out / "run1", out / "run2", files);
  std::printf("determinism: %s, %d frames, budget %lld tests: two runs %s (%d files compared)\n",
              scene.name.c_str(), frames, budget, diff.empty() ? "identical" : "DIFFER", files);
  if (!diff.empty()) {
    std::printf("  first difference: %s\n", diff.c_str());
    ok = false;
  }

  int contacts1 = 0, contacts2 = 0;
  const std::vector<std::string> t1 = world_trace(scene, 1, contacts1);
  const std::vector<std::string> t2 = world_trace(scene, 2, contacts2);
  int first = -1;
  for (size_t f = 0; f < t1.size() && first < 0; ++f)
    if (f >= t2.size() || t1[f] != t2[f]) first = static_cast<int>(f);
  std::printf("determinism: 1 vs 2 FEM threads: %s", first < 0 ? "identical" : "DIFFER");
  if (first >= 0) std::printf(" from frame %d", first);
  std::printf(" (%zu frames of metrics and positions compared, %d with contact)\n", t1.size(),
              contacts1);
  ok = ok && first < 0;
  if (contacts1 == 0) {  // without contact the check proves little
    std::printf("determinism: no frame had contact; use more frames\n");
    ok = false;
  }
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("determinism", run, argc, argv);
}
