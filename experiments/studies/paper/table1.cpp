// table1: reproduces the paper's Table 1. For each interaction (scene) and
// each critical time, a fresh run from identical initial conditions is taken
// to the same moment of contact; we record PAIRLIST and COLLISIONLIST sizes
// there, and the frame rate over the contact window, and print them next to
// the paper's numbers. Writes table1.csv and table1.md into --out.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <icd/config.hpp>
#include <icd/mesh/io/atomic_write.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/runner/run.hpp"

namespace fs = std::filesystem;
using namespace icd::runner;

namespace {

// The paper's Table 1: critical time -> {pairList, collisionList, FPS} per interaction.
struct PaperRow {
  int pair_list, collision_list, fps;
};
const std::map<std::string, std::map<double, PaperRow>> kPaper = {
    {"dragon_dragon",
     {{1e-4, {3, 0, 60}},
      {1e-3, {17, 0, 60}},
      {1e-2, {30, 0, 42}},
      {1e-1, {41, 6, 35}},
      {1, {1345, 30, 25}}}},
    {"bunny_bunny",
     {{1e-4, {3, 0, 52}},
      {1e-3, {25, 0, 48}},
      {1e-2, {44, 0, 37}},
      {1e-1, {61, 11, 30}},
      {1, {1405, 36, 22}}}},
    {"bunny_dragon",
     {{1e-4, {3, 0, 56}},
      {1e-3, {21, 0, 51}},
      {1e-2, {33, 0, 42}},
      {1e-1, {52, 12, 33}},
      {1, {1387, 28, 23}}}},
};

// A message as one CSV field / one Markdown table cell.
std::string csv_text(std::string s) {
  for (char& c : s)
    if (c == ',' || c == '\n' || c == '"') c = ';';
  return s;
}
std::string md_text(std::string s) {
  for (char& c : s)
    if (c == '|' || c == '\n') c = ';';
  return s;
}

struct Row {
  std::string scene;
  double budget = 0;
  bool tests = false;  // budget is a number of sphere tests (deterministic), not seconds
  std::string failure;  // the simulation's error, if it failed before the measured frame
  int failed_frame = -1;
  int contact_frame = -1, measure_frame = -1;
  FrameMetrics at;          // metrics of the measured frame
  double fps = 0;           // frames per wall second over the contact window
  double collision_ms = 0;  // mean collision time per frame in the window
};

int run(int argc, char** argv) {
  fs::path out = "results/table1";
  std::vector<fs::path> scenes;
  std::vector<double> budgets = {1e-4, 1e-3, 1e-2, 1e-1, 1.0};
  std::vector<double> test_budgets;  // deterministic twin: budgets in sphere tests
  bool time_budgets_given = false;
  int max_frames = 200, after = 3;
  double paper_scale = 1;  // our critical time x paper_scale = the paper's row we sit beside
  std::vector<std::string> overrides;  // --set
  icd::experiments::Cli cli(
      "table1",
      "  Runs each scene once per critical time (default 1e-4,1e-3,1e-2,1e-1,1 s) and\n"
      "  records the list sizes N frames (--after, default 3) after first contact.\n"
      "  Default scenes: the paper's dragon-dragon, bunny-bunny, bunny-dragon.");
  cli.path("--out", out, "DIR", "output folder (default results/table1)")
      .custom("--scene", "FILE", "a scene to run (repeatable)",
              [&](const std::string& v) { scenes.emplace_back(v); })
      .custom("--budgets", "a,b,...", "critical times (s)",
              [&](const std::string& v) {
                budgets.clear();
                time_budgets_given = true;
                std::stringstream ss(v);
                for (std::string t; std::getline(ss, t, ',');)
                  budgets.push_back(icd::experiments::Cli::parse_real(t, 0.0));
                if (budgets.empty()) throw std::invalid_argument("needs at least one time");
              })
      .custom("--test-budgets", "a,b,...",
              "budgets in sphere tests (deterministic: the same lists on any machine); alone, "
              "they replace the default critical times",
              [&](const std::string& v) {
                std::stringstream ss(v);
                for (std::string t; std::getline(ss, t, ',');)
                  test_budgets.push_back(icd::experiments::Cli::parse_real(t, 1.0));
                if (test_budgets.empty()) throw std::invalid_argument("needs at least one count");
              })
      .integer("--max-frames", max_frames, "N", "frames searched for contact (default 200)", 1)
      .real("--paper-scale", paper_scale, "F",
            "the paper's row at critical time x F sits beside ours (default 1)", 0.0)
      .integer("--after", after, "N", "frames after first contact (default 3)", 0);
  cli.scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  if (!test_budgets.empty() && !time_budgets_given) budgets.clear();
  std::vector<std::pair<bool, double>> all;  // (tests?, budget)
  for (double b : budgets) all.emplace_back(false, b);
  for (double b : test_budgets) all.emplace_back(true, b);
  if (scenes.empty())
    for (const char* s : {"dragon_dragon", "bunny_bunny", "bunny_dragon"})
      scenes.push_back(fs::path(ICD_SOURCE_DIR) / "experiments/scenes" /
                       (std::string(s) + ".json"));
  const fs::path cache = fs::path(ICD_SOURCE_DIR) / "assets";
  const fs::path tools = fs::canonical("/proc/self/exe").parent_path();
  std::vector<Row> rows;
  for (const fs::path& sp : scenes) {
    Scene scene = load_scene(sp, overrides);
    scene.output = OutputSpec{};
    scene.output.csv = false;
    scene.world.target_fps = 0;
    for (const auto& [tests, budget] : all) {
      scene.world.collision.query.budget_tests = tests ? static_cast<int64_t>(budget) : -1;
      scene.world.collision.query.budget_seconds =
          tests ? std::numeric_limits<double>::infinity() : budget;
      World world = make_world(scene, cache, tools);
      Row row;
      row.scene = scene.name;
      row.budget = budget;
      row.tests = tests;
      std::vector<FrameMetrics> frames;
      try {
        for (int f = 0; f < max_frames; ++f) {
          frames.push_back(world.step());
          // Contact: some sphere pair produced a force.
          if (row.contact_frame < 0 && frames.back().active_pairs > 0) row.contact_frame = f;
          if (row.contact_frame >= 0 && f == row.contact_frame + after) break;
        }
      } catch (const std::exception& e) {
        // A run that fails is a result (recorded, marked), not the end of the table.
        row.failure = e.what();
        row.failed_frame = static_cast<int>(frames.size());
        std::fprintf(stderr, "table1: %s at %g%s: failed in frame %d: %s\n", scene.name.c_str(),
                     budget, tests ? " tests" : " s", row.failed_frame, e.what());
        rows.push_back(row);
        continue;
      }
      if (row.contact_frame < 0) {
        std::fprintf(stderr, "table1: %s at %g s: no contact within %d frames\n",
                     scene.name.c_str(), budget, max_frames);
        row.at = frames.back();
      } else {
        row.measure_frame = static_cast<int>(frames.size()) - 1;
        row.at = frames.back();
        double wall = 0, coll = 0;
        for (int f = row.contact_frame; f <= row.measure_frame; ++f) {
          wall += frames[f].wall;
          coll += frames[f].times.collision;
        }
        const int n = row.measure_frame - row.contact_frame + 1;
        row.fps = n / wall;
        row.collision_ms = 1e3 * coll / n;
      }
      std::printf(
          "%-14s budget %-7g%s contact frame %3d: PAIRLIST %6lld COLLISIONLIST %5lld fps %6.1f\n",
          row.scene.c_str(), budget, tests ? " tests" : " s", row.contact_frame,
          static_cast<long long>(row.at.pair_list), static_cast<long long>(row.at.collision_list),
          row.fps);
      std::fflush(stdout);
      rows.push_back(row);
    }
  }

  std::ostringstream csv, md;
  csv << "scene,critical_time,contact_frame,measure_frame,pair_list,collision_list,fps,"
         "collision_ms,tests,interrupted,completed_level,paper_pair_list,paper_collision_list,"
         "paper_fps,budget_kind,failure\n";
  md << "| interaction | critical time (s) or test budget | PAIRLIST ours | paper | COLLISIONLIST ours | paper | "
        "FPS ours | paper | completed level |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    const auto ps = kPaper.find(r.scene);
    const PaperRow* p = nullptr;
    if (ps != kPaper.end() && !r.tests) {
      for (const auto& [t, row] : ps->second)
        if (std::abs(t - r.budget * paper_scale) <= 1e-9 * t) p = &row;
    }
    csv << r.scene << ',' << r.budget << ',' << r.contact_frame << ',' << r.measure_frame << ','
        << r.at.pair_list << ',' << r.at.collision_list << ',' << r.fps << ',' << r.collision_ms
        << ',' << r.at.tests << ',' << r.at.interrupted << ',' << r.at.completed_level << ','
        << (p ? std::to_string(p->pair_list) : "") << ','
        << (p ? std::to_string(p->collision_list) : "") << ',' << (p ? std::to_string(p->fps) : "")
        << ',' << (r.tests ? "tests" : "seconds") << ',' << csv_text(r.failure) << '\n';
    char fps[32];
    std::snprintf(fps, sizeof fps, "%.1f", r.fps);
    std::ostringstream budget;
    budget << r.budget << (r.tests ? " tests" : "");
    if (!r.failure.empty()) {
      md << "| " << r.scene << " | " << budget.str() << " | FAILED in frame " << r.failed_frame
         << " (first contact " << r.contact_frame << "): " << md_text(r.failure)
         << " | | | | | | |\n";
      continue;
    }
    md << "| " << r.scene << " | " << budget.str() << " | " << r.at.pair_list << " | "
       << (p ? std::to_string(p->pair_list) : "-") << " | " << r.at.collision_list << " | "
       << (p ? std::to_string(p->collision_list) : "-") << " | " << fps << " | "
       << (p ? std::to_string(p->fps) : "-") << " | " << r.at.completed_level << " |\n";
  }
  fs::create_directories(out);
  icd::write_file_atomically(out / "table1.csv", csv.str());
  icd::write_file_atomically(out / "table1.md", md.str());
  std::printf("\n%s\nresults: %s\n", md.str().c_str(), fs::absolute(out).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("table1", run, argc, argv);
}
