// Reduced versions of the issue-8 experiment programs: each runs on the
// two_spheres scene (or small primitive objects) for a few frames, and its
// CSV output is checked against properties that must hold whatever the
// timing: no NaN, fractions in [0, 1], unlimited budgets reproduce the
// uninterrupted traversal (independent traversal orders), interrupted
// answers stay conservative, identical resolutions give identical surfaces.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using Row = std::map<std::string, std::string>;

// Splits one CSV line (quoted fields may hold commas).
std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"')
      quoted = !quoted;
    else if (c == ',' && !quoted)
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

std::vector<Row> read_csv(const fs::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << "missing " << path;
  std::string line;
  std::vector<Row> rows;
  if (!std::getline(in, line)) return rows;
  const std::vector<std::string> header = split_csv(line);
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = split_csv(line);
    EXPECT_EQ(cells.size(), header.size()) << path << ": " << line;
    Row r;
    for (size_t k = 0; k < header.size() && k < cells.size(); ++k) r[header[k]] = cells[k];
    rows.push_back(r);
  }
  return rows;
}

double num(const Row& r, const std::string& key) {
  const auto it = r.find(key);
  EXPECT_NE(it, r.end()) << "no column " << key;
  if (it == r.end()) return std::numeric_limits<double>::quiet_NaN();
  return std::stod(it->second);
}

// A fresh output folder per test.
fs::path out_dir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("icd_exp_reduced_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

int run(const std::string& program, const std::string& args, const fs::path& out) {
  const std::string cmd = std::string(ICD_EXP_BIN_DIR) + "/" + program + " --out " + out.string() +
                          " " + args + " > " + (out / "log.txt").string() + " 2>&1";
  return std::system(cmd.c_str());
}

std::string log_of(const fs::path& out) {
  std::ifstream in(out / "log.txt");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const std::string kScene = std::string(ICD_EXP_SOURCE_DIR) + "/experiments/scenes/two_spheres.json";

bool python_has_plotting() {
  return std::system("/usr/bin/python3 -c 'import meshio, matplotlib, numpy' > /dev/null 2>&1") ==
         0;
}

TEST(ExperimentsReduced, Table1) {
  const fs::path out = out_dir("table1");
  ASSERT_EQ(run("table1", "--scene " + kScene + " --budgets 1e-3 --max-frames 20 --after 1", out),
            0)
      << log_of(out);
  const auto rows = read_csv(out / "table1.csv");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_GE(num(rows[0], "contact_frame"), 0);
  EXPECT_GT(num(rows[0], "pair_list") + num(rows[0], "collision_list"), 0);
  EXPECT_GT(num(rows[0], "fps"), 0);
}

TEST(ExperimentsReduced, Fig9) {
  const fs::path out = out_dir("fig9");
  ASSERT_EQ(
      run("fig9", "--scene " + kScene + " --budgets 1e-5,1e-2 --max-frames 20 --after 1", out), 0)
      << log_of(out);
  const auto rows = read_csv(out / "manifest.csv");
  ASSERT_EQ(rows.size(), 2u);
  for (const Row& r : rows) {
    EXPECT_GE(num(r, "contact_frame"), 0);
    for (const char* key : {"objects", "spheres"}) {
      std::stringstream ss(r.at(key));
      for (std::string f; std::getline(ss, f, ';');)
        EXPECT_TRUE(fs::exists(out / r.at("dir") / f)) << f;
    }
  }
  if (!python_has_plotting())
    GTEST_SKIP() << "/usr/bin/python3 lacks meshio/matplotlib: plot not checked";
  const std::string cmd = "/usr/bin/python3 " + std::string(ICD_EXP_SOURCE_DIR) +
                          "/scripts/plot_fig9.py " + out.string() + " --max-faces 2000 > " +
                          (out / "plot.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_GT(fs::file_size(out / "fig9.png"), 1000u);
}

TEST(ExperimentsReduced, ContactError) {
  const fs::path out = out_dir("contact");
  // A soft penalty, without the per-node rate cap and the inelastic deep step
  // (both stop the approach), so that the dense surfaces interpenetrate and the
  // exact triangle reference is not empty.
  std::ifstream in(kScene);
  std::stringstream text;
  text << in.rdbuf();
  std::string json = text.str();
  const size_t at = json.find("\"stiffness\": 2000");
  ASSERT_NE(at, std::string::npos) << "two_spheres.json changed: update this test";
  json.replace(at, std::string("\"stiffness\": 2000").size(),
               "\"stiffness\": 20, \"node_rate_cap\": false, \"deep_step_ratio\": 0");
  std::ofstream(out / "soft.json") << json;
  ASSERT_EQ(
      run("contact_error",
          "--scene " + (out / "soft.json").string() +
              " --budgets 1e-5,1e-3 --test-budgets 20,100000000 --reps 1 --max-frames 20 --after 3",
          out),
      0)
      << log_of(out);
  const auto rows = read_csv(out / "contact_error.csv");
  ASSERT_EQ(rows.size(), 5u * 4u);  // 5 modes x (2 time + 2 test budgets)
  for (const Row& r : rows) {
    for (const char* key : {"recall_full", "recall_exact", "false_positive"}) {
      EXPECT_GE(num(r, key), 0) << key;
      EXPECT_LE(num(r, key), 1) << key;
    }
    EXPECT_TRUE(std::isfinite(num(r, "force_rel_error")));
    EXPECT_GT(num(r, "exact_pairs"), 0) << "the moment of contact has no exact triangle contact";
    // Conservative: whatever the budget, the reported pairs cover at least what
    // the full traversal's leaves cover (layered trees: parents hold children).
    const double full_recall_of_exact = [&] {
      for (const Row& q : rows)
        if (q.at("mode") == "fifo" && q.at("budget_kind") == "tests" && num(q, "interrupted") == 0)
          return num(q, "recall_exact");
      return std::numeric_limits<double>::quiet_NaN();
    }();
    EXPECT_GE(num(r, "recall_exact"), full_recall_of_exact - 1e-12)
        << r.at("mode") << " " << r.at("budget");
    EXPECT_DOUBLE_EQ(num(r, "recall_full"), 1.0)
        << "interrupted answers must cover every colliding leaf pair";
    // An unlimited budget reaches the same leaves in every mode (different orders).
    if (r.at("budget_kind") == "tests" && num(r, "budget") > 1e7) {
      EXPECT_EQ(num(r, "interrupted"), 0) << r.at("mode");
      EXPECT_LT(num(r, "force_rel_error"), 1e-9) << r.at("mode");
      EXPECT_EQ(num(r, "reported_pairs"), num(r, "full_leaf_pairs")) << r.at("mode");
    }
  }
}

TEST(ExperimentsReduced, DeformationError) {
  const fs::path out = out_dir("deformation");
  ASSERT_EQ(run("deformation_error",
                "--scene " + kScene + " --resolution-scene " + kScene +
                    " --frames 4 --reps 1 --cells 2,4 --fine 4",
                out),
            0)
      << log_of(out);
  const auto links = read_csv(out / "links.csv");
  ASSERT_EQ(links.size(), 2u * 4u);  // two deformable objects x 4 frames
  for (const Row& r : links) {
    EXPECT_GE(num(r, "rms_error"), 0);
    EXPECT_GE(num(r, "max_error"), num(r, "rms_error"));
    EXPECT_LT(num(r, "max_error_pct_bbox"), 100)
        << "links and barycentric surfaces should be close";
    // Before contact the motion is a translation, which both mappings reproduce exactly.
    if (num(r, "frame") == 0 && num(r, "active_pairs") == 0) {
      EXPECT_LT(num(r, "max_error_pct_bbox"), 1e-9);
    }
  }
  const auto res = read_csv(out / "resolution.csv");
  ASSERT_EQ(res.size(), 2u);
  EXPECT_GT(num(res[0], "rms_error"), 0) << "a coarser grid must change the surface";
  EXPECT_EQ(num(res[1], "max_error"), 0)
      << "the same resolution must reproduce the reference exactly";
}

TEST(ExperimentsReduced, SphereUpdate) {
  const fs::path out = out_dir("sphere_update");
  ASSERT_EQ(run("sphere_update_error", "--scene " + kScene + " --frames 4 --reps 1", out), 0)
      << log_of(out);
  const auto rows = read_csv(out / "sphere_update.csv");
  ASSERT_EQ(rows.size(), 4u * 2u * 3u);  // frames x objects x methods
  for (const Row& r : rows) {
    EXPECT_GE(num(r, "uncovered_fraction"), 0);
    EXPECT_LE(num(r, "uncovered_fraction"), 1);
    EXPECT_GT(num(r, "tightness"), 0);
    // The octree builder covers its surface exactly, so the rebuilt tree
    // leaves no dense vertex uncovered (measured by an independent grid).
    if (r.at("method") == "rebuild_octree") {
      EXPECT_EQ(num(r, "uncovered_fraction"), 0);
    }
  }
  // Before contact the objects only translate: the updated trees equal the
  // tree rebuilt on the moved surface (same builder), so their tightness agrees.
  for (const Row& r : rows)
    if (num(r, "frame") == 0 && r.at("method") != "rebuild_octree")
      for (const Row& q : rows)
        if (num(q, "frame") == 0 && q.at("method") == "rebuild_octree" &&
            q.at("object") == r.at("object")) {
          EXPECT_NEAR(num(r, "tightness"), num(q, "tightness"), 1e-6 * num(q, "tightness"))
              << r.at("method");
        }
}

TEST(ExperimentsReduced, StabilitySweep) {
  const fs::path out = out_dir("stability");
  ASSERT_EQ(run("stability_sweep", "--quick --frames 3 --max-seconds 3", out), 0) << log_of(out);
  const auto rows = read_csv(out / "stability.csv");
  ASSERT_GE(rows.size(), 6u);
  int stable = 0;
  for (const Row& r : rows) {
    const std::string s = r.at("status");
    EXPECT_TRUE(s == "stable" || s == "unstable" || s == "error" || s == "timeout") << s;
    if (s != "stable") {
      EXPECT_FALSE(r.at("message").empty()) << r.at("case") << ": failure without a message";
    }
    stable += s == "stable";
    for (const auto& [k, v] : r)
      if (k != "message" && k != "case") {
        EXPECT_EQ(v.find("nan"), std::string::npos) << k << " = " << v;
      }
  }
  EXPECT_GT(stable, 0);
  EXPECT_TRUE(fs::exists(out / "stability.md"));
}

// A program given a bad command line (in `cases`) must stop with status 2,
// print the expected message in the one wording "<program>: ... (see --help)",
// and leave nothing but the log in
// its output folder. `fem`: the program is one of the FEM experiments (their
// own folder; they take no --out and write into the working folder).
struct BadCommandLine {
  std::string program, args, expected;
};

void expect_refused(const std::vector<BadCommandLine>& cases, bool fem) {
  for (const BadCommandLine& c : cases) {
    const fs::path out = out_dir("bad_" + c.program);
    const int status =
        fem ? std::system(("cd " + out.string() + " && " + std::string(ICD_FEM_BIN_DIR) + "/" +
                           c.program + " " + c.args + " > log.txt 2>&1")
                              .c_str())
            : run(c.program, c.args, out);
    const std::string log = log_of(out);
    ASSERT_TRUE(WIFEXITED(status)) << c.program;
    EXPECT_EQ(WEXITSTATUS(status), 2) << c.program << " " << c.args << ": " << log;
    EXPECT_NE(log.find(c.expected), std::string::npos) << c.program << ": " << log;
    EXPECT_NE(log.find(c.program + ": " + c.expected), std::string::npos) << c.program << ": " << log;
    EXPECT_NE(log.find(" (see --help)\n"), std::string::npos) << c.program << ": " << log;
    for (const auto& entry : fs::directory_iterator(out))
      EXPECT_EQ(entry.path().filename(), "log.txt") << c.program << " wrote " << entry.path();
  }
}

TEST(ExperimentsReduced, BadOptionsStopWithStatusTwoAndNameTheOption) {
  // The programs parse their options with experiments/common/cli.hpp:
  // a malformed number, a value out of range, a missing value or an unknown
  // option is reported with the option's name before anything runs.
  expect_refused(
      {
          {"table1", "--max-frames 12x", "--max-frames expects a whole number, got '12x'"},
          {"fig9", "--after -1", "--after must be in [0, "},
          {"contact_error", "--reps 0", "--reps must be in [1, "},
          {"deformation_error", "--frobnicate 3", "unknown option '--frobnicate'"},
          {"sphere_update_error", "--every", "--every needs a value"},
          {"stability_sweep", "--max-seconds nan", "--max-seconds expects a finite number"},
      },
      false);
}

TEST(ExperimentsReduced, FemProgramsCheckTheirArguments) {
  // The FEM experiments take positional arguments (fem_realtime [bar|block]
  // [THREADS], fem_error_vs_time [OUT.csv] [--quick], fem_compression
  // [OUTPUT]); a bad one stops them before they write anything.
  expect_refused(
      {
          {"fem_realtime", "slab", "MESH must be bar or block, got 'slab'"},
          {"fem_realtime", "block 0", "THREADS must be in [1, 256], got '0'"},
          {"fem_realtime", "bar 2x", "THREADS expects a whole number, got '2x'"},
          {"fem_error_vs_time", "a.csv --quick b.csv", "unexpected argument 'b.csv'"},
          {"fem_error_vs_time", "--fast", "unknown option '--fast'"},
          {"fem_compression", "x.txt y.txt", "unexpected argument 'y.txt'"},
      },
      true);
}

}  // namespace
