// Hostile scenes and command lines for the runner: paths are data (no shell
// ever sees them), names are not paths, a frame count of 0 is refused
// everywhere, dry runs check the input paths, failures name the object, and
// a unit mismatch between objects gets a warning naming the object.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <icd/mesh/core/error.hpp>
#include "experiments/runner/object_asset.hpp"
#include "experiments/runner/run.hpp"

namespace icd::runner {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string ball(const std::string& name, double x, double v, const std::string& extra = "") {
  std::ostringstream s;
  s << R"({"name": ")" << name
    << R"(", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 1, "cells": 3},)"
    << R"( "position": [)" << x << R"(, 0, 0], "velocity": [)" << v
    << R"(, 0, 0], "material": {"model": "stvk", "young": 5e5, "poisson": 0.3, "density": 1000},)"
    << R"( "preprocess": {"tree_depth": 2})" << extra << "}";
  return s.str();
}

std::string scene_text(const std::string& name, const std::string& objects,
                       const std::string& extra = "") {
  return R"({"name": ")" + name + R"(", "frames": 1, "objects": [)" + objects +
         R"(], "collision": {"budget_tests": 1000})" + (extra.empty() ? "" : ", " + extra) + "}";
}

Scene parse(const std::string& text) {
  return parse_scene(parse_json(text, "s.json"), "s.json", ".");
}

RunOptions quiet_options(const fs::path& out) {
  RunOptions o;
  o.out_dir = out;
  o.cache_dir = out / "cache";
  o.tool_dir = out / "tools";
  o.progress = false;
  o.log = nullptr;
  return o;
}

// --- child processes ----------------------------------------------------------

// The raw mesh's path reaches icd-preprocess as one argument, byte for byte:
// no shell expands `$(...)`, backticks or quotes in it. A stand-in tool
// records its arguments and fails.
TEST(HostileRunner, PreprocessingPassesThePathAsDataNotToAShell) {
  const fs::path dir = fresh_dir("icd_hostile_shell");
  const fs::path tools = dir / "tools";
  fs::create_directories(tools);
  write(tools / "icd-preprocess",
        "#!/bin/sh\nprintf '%s\\n' \"$@\" > \"$(dirname \"$0\")/args.txt\"\nexit 3\n");
  fs::permissions(tools / "icd-preprocess", fs::perms::owner_all);
  const fs::path marker = fs::current_path() / "icd_injected_marker";
  // A command substitution alone (a shell runs it), then quotes and backticks
  // as well (they broke the shell command line).
  for (const std::string& name : {std::string("x$(touch icd_injected_marker).off"),
                                  std::string("y$(touch icd_injected_marker)\"`touch "
                                              "icd_injected_marker`'.off")}) {
    fs::remove(marker);
    fs::remove(tools / "args.txt");
    ObjectSpec spec;
    spec.name = "evil";
    spec.mesh = dir / name;
    write(spec.mesh,
          "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
    try {
      load_object_asset(spec, dir / "cache", tools);
      ADD_FAILURE() << "a failing preprocessor was not reported";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("object \"evil\""), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(marker)) << "a shell ran the mesh path " << name;
    fs::remove(marker);
    std::istringstream args(read(tools / "args.txt"));
    std::string first;
    std::getline(args, first);
    EXPECT_EQ(first, spec.mesh.string());
  }
}

// --- frame counts ---------------------------------------------------------------

TEST(HostileRunner, RunSceneRefusesZeroFrames) {
  const fs::path dir = fresh_dir("icd_hostile_frames");
  RunOptions opt = quiet_options(dir / "out");
  opt.frames = 0;
  try {
    run_scene(parse(scene_text("zero", ball("a", 0, 0))), opt);
    ADD_FAILURE() << "0 frames accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("frames"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "frames.csv"));
}

// --- names are not paths ---------------------------------------------------------

// Object names become file names of the VTU series: a name with "../" or an
// absolute name writes inside the output folder all the same.
TEST(HostileRunner, ObjectNamesDoNotWriteOutsideTheOutputFolder) {
  const fs::path dir = fresh_dir("icd_hostile_names");
  const fs::path out = dir / "a" / "b" / "out";
  const fs::path absolute = dir / "absolute_escape";
  run_scene(parse(scene_text("names",
                             ball("../../escaped", -0.3, 0) + "," + ball(absolute.string(), 0.3, 0),
                             R"("output": {"vtu_every": 1})")),
            quiet_options(out));
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const fs::path rel = fs::relative(e.path(), dir);
    EXPECT_TRUE(rel == "a" || rel == "a/b" || rel.string().starts_with("a/b/out"))
        << "written outside the output folder: " << e.path();
  }
  int vtu = 0;
  for (const auto& e : fs::directory_iterator(out / "vtu")) vtu += e.path().extension() == ".vtu";
  EXPECT_GE(vtu, 4);  // coarse and dense of both objects at least
}

// --- failures name the object -------------------------------------------------------

TEST(HostileRunner, FemFailureNamesTheObject) {
  World world =
      make_world(parse(scene_text("fem", ball("left", -0.3, 0) + "," + ball("right", 0.3, 0))),
                 "/nonexistent", "/nonexistent");
  RuntimeObject& right = world.objects()[1];
  right.sim->set_positions(-right.sim->positions());  // every element inverted
  try {
    world.step();
    ADD_FAILURE() << "an inverted object was not reported";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("object \"right\""), std::string::npos) << e.what();
  }
}

// --- scale ------------------------------------------------------------------------------

// A 0.3 m ball beside an object 1000 times larger (an asset left in
// millimetres): a warning naming the large object; none for matching sizes.
TEST(HostileRunner, ScaleMismatchGetsAWarningNamingTheObject) {
  const std::string huge =
      R"({"name": "huge", "kind": "static", "primitive": {"type": "box", "extent": [300, 300, 300],)"
      R"( "subdivisions": 1, "cells": 2}, "position": [0.5, 0, 0], "preprocess": {"tree_depth": 1}})";
  ::testing::internal::CaptureStderr();
  make_world(parse(scene_text("scale", ball("ball", 0, 0) + "," + huge)), "/nonexistent",
             "/nonexistent");
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("warning"), std::string::npos) << err;
  EXPECT_NE(err.find("\"huge\""), std::string::npos) << err;

  ::testing::internal::CaptureStderr();
  make_world(parse(scene_text("ok", ball("left", -0.3, 0) + "," + ball("right", 0.3, 0))),
             "/nonexistent", "/nonexistent");
  const std::string none = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(none.find("warning"), std::string::npos) << none;
}

// --- the icd-run program ----------------------------------------------------------------

struct Outcome {
  int status = -1;
  std::string output;
};

// Runs icd-run in `cwd` with `args` (test-made, no quotes needed).
Outcome icd_run(const fs::path& cwd, const std::string& args) {
  const fs::path log = cwd / "icd_run.log";
  const std::string cmd =
      "cd '" + cwd.string() + "' && '" ICD_RUN_EXE "' " + args + " > '" + log.string() + "' 2>&1";
  const int raw = std::system(cmd.c_str());
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, read(log)};
}

TEST(HostileRunner, CommandLineFramesZeroIsRefusedAsInTheSceneFile) {
  const fs::path dir = fresh_dir("icd_hostile_cli_frames");
  write(dir / "s.json", scene_text("cli", ball("a", 0, 0)));
  const Outcome r = icd_run(dir, "s.json --frames 0 --out out --quiet");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("[1, "), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out" / "frames.csv"));
}

TEST(HostileRunner, DryRunChecksEveryInputPath) {
  const fs::path dir = fresh_dir("icd_hostile_dry");
  write(dir / "s.json",
        scene_text("dry", ball("a", -0.3, 0) + R"(, {"name": "b", "mesh": "no_such_mesh.off"})"));
  const Outcome r = icd_run(dir, "s.json --dry-run --quiet");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("object \"b\""), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no_such_mesh.off: cannot open file"), std::string::npos) << r.output;
}

// Without --out the results go to results/<name>: a name with "../" or an
// absolute name stays inside results/.
TEST(HostileRunner, SceneNamesStayInsideResults) {
  const fs::path dir = fresh_dir("icd_hostile_scene_names");
  const fs::path work = dir / "a" / "b";
  fs::create_directories(work);
  const fs::path absolute = dir / "absolute_escape";
  for (const std::string& name : {std::string("../../escaped"), absolute.string()}) {
    write(work / "s.json", scene_text(name, ball("a", 0, 0)));
    const Outcome r = icd_run(work, "s.json --quiet");
    EXPECT_EQ(r.status, 0) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "escaped"));
  EXPECT_FALSE(fs::exists(absolute));
  int runs = 0;
  for (const auto& e : fs::directory_iterator(work / "results"))
    runs += fs::exists(e.path() / "frames.csv");
  EXPECT_EQ(runs, 2);
}

}  // namespace
}  // namespace icd::runner
