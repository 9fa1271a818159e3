// faults: the fault cases of issue 9, each run through the runner's World on
// two small deformable balls (budget in sphere tests, so runs are
// reproducible). Each case must either be handled -- every frame runs, all
// positions and energies stay finite -- or stop with a clear diagnostic
// (icd::InputError / ParameterError / NumericalError naming the problem).
// Prints per case the outcome, frames run, the largest total energy (J) and
// the frames with contact, so that "handled" can be judged.
// A silent NaN or any other exception is a failure (exit 1).
// usage: faults [--frames N=120]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <typeinfo>
#include <vector>

#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/runner/scene.hpp"
#include "experiments/runner/run.hpp"
#include <icd/config.hpp>
#include <icd/mesh/core/error.hpp>

namespace {

using namespace icd;

struct Case {
  std::string name;
  std::string what;  // the documented expectation
  double left_x = -0.13, right_x = 0.13, speed = 0.6;
  std::string collision = R"("budget_tests": 2000)";
  bool fix_all_left = false;
  std::string model = "stvk";  // material of both balls
  double kick_at_half = 0;     // m/s added to every left-ball node at the middle frame
};

runner::Scene make_scene(const Case& c) {
  std::ostringstream s;
  s.precision(17);
  auto ball = [&](const char* name, double x, double v) {
    s << R"({"name": ")" << name
      << R"(", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 2, "cells": 4},)"
      << R"( "position": [)" << x << R"(, 0, 0], "velocity": [)" << v
      << R"(, 0, 0], "material": {"model": ")" << c.model << R"(", "young": 5e5, "poisson": 0.3,)"
      << R"( "density": 1000}, "integrator": "rk4", "preprocess": {"tree_depth": 3}})";
  };
  s << R"({"name": ")" << c.name << R"(", "frames": 1, "objects": [)";
  ball("left", c.left_x, c.speed);
  s << ",";
  ball("right", c.right_x, -c.speed);
  s << R"(], "collision": {)" << c.collision << R"(, "stiffness": 2000, "layered": true}})";
  return runner::parse_scene(runner::parse_json(s.str(), c.name), c.name, ".");
}

struct Outcome {
  std::string status;  // handled / diagnostic / FAILED
  int frames = 0;
  double max_energy = 0;
  int contact_frames = 0;
  std::string message;
};

Outcome run_case(const Case& c, int frames) {
  Outcome out;
  try {
    runner::Scene scene = make_scene(c);
    if (c.fix_all_left) {
      // Learn the coarse node count, then fix every node of the left ball.
      runner::World probe = runner::make_world(scene, ICD_SOURCE_DIR "/assets", ICD_TOOL_DIR);
      const int n = static_cast<int>(probe.objects()[0].positions.rows());
      for (int i = 0; i < n; ++i) scene.objects[0].fixed_nodes.push_back(i);
    }
    runner::World world = runner::make_world(scene, ICD_SOURCE_DIR "/assets", ICD_TOOL_DIR);
    for (int f = 0; f < frames; ++f) {
      if (c.kick_at_half != 0 && f == frames / 2) {
        // A huge force over one step is an impulse: applied as a velocity
        // jump (the World overwrites external forces with contact forces).
        runner::RuntimeObject& o = world.objects()[0];
        MatX3d v = o.sim->velocities();
        v.col(0).array() += c.kick_at_half;
        o.sim->set_velocities(v);
      }
      const runner::FrameMetrics m = world.step();
      bool finite = std::isfinite(m.energy) && std::isfinite(m.max_penetration);
      for (runner::RuntimeObject& o : world.objects()) finite = finite && o.positions.allFinite();
      if (!finite) {
        out.status = "FAILED";
        out.message = "silent non-finite state at frame " + std::to_string(f);
        return out;
      }
      out.frames = f + 1;
      out.max_energy = std::max(out.max_energy, m.energy);
      out.contact_frames += m.active_pairs > 0;
    }
    out.status = "handled";
  } catch (const InputError& e) {
    out.status = "diagnostic";
    out.message = std::string("InputError: ") + e.what();
  } catch (const ParameterError& e) {
    out.status = "diagnostic";
    out.message = std::string("ParameterError: ") + e.what();
  } catch (const NumericalError& e) {
    out.status = "diagnostic";
    out.message = std::string("NumericalError: ") + e.what();
  } catch (const std::exception& e) {
    out.status = "FAILED";
    out.message = std::string("undocumented ") + typeid(e).name() + ": " + e.what();
  }
  if (out.status == "diagnostic" && out.message.find(": ") + 2 >= out.message.size())
    out.status = "FAILED";  // an empty message is no diagnostic
  return out;
}

int run(int argc, char** argv) {
  int frames = 120;
  icd::experiments::Cli cli("faults", "  Fault cases of the full loop, each reported.");
  cli.integer("--frames", frames, "N", "frames per case (default 120)", 1);
  if (const auto status = cli.parse(argc, argv)) return *status;
  std::vector<Case> cases;
  cases.push_back({"zero_budget", "budget of 0 sphere tests: refused at scene validation"});
  cases.back().collision = R"("budget_tests": 0)";
  cases.push_back({"huge_budget", "budget of 10^12 sphere tests"});
  cases.back().collision = R"("budget_tests": 1000000000000)";
  cases.push_back({"unlimited_time_budget", "no budget at all (\"unlimited\": true)"});
  cases.back().collision = R"("unlimited": true)";
  cases.push_back({"all_nodes_fixed", "left ball fully fixed: acts as a wall"});
  cases.back().fix_all_left = true;
  // Overlapping starts: the passive response (default) gives back only the
  // work the contact absorbed, so balls overlapping at rest drift apart from
  // one cycle's push (the energy column counts the deep springs' energy the
  // balls never receive); "passive": false releases the springs' energy (the
  // paper's response).
  const char* raw = R"("budget_tests": 2000, "passive": false)";
  const auto overlapping = [&](const char* name, const char* what, const char* collision) {
    cases.push_back({name, what});
    cases.back().left_x = -0.075;
    cases.back().right_x = 0.075;
    cases.back().speed = 0;
    if (collision) cases.back().collision = collision;
  };
  cases.push_back({"coincident_centres", "both balls at the same place"});
  cases.back().left_x = cases.back().right_x = 0;
  cases.push_back({"coincident_centres_raw", "as above, \"passive\": false"});
  cases.back().left_x = cases.back().right_x = 0;
  cases.back().collision = raw;
  overlapping("start_interpenetrated", "balls overlap by half a radius at t = 0, at rest", nullptr);
  overlapping("start_interpenetrated_raw", "as above, \"passive\": false", raw);
  overlapping("start_interpenetrated_snh_raw",
              "as above, inversion-safe stable Neo-Hookean: pushed apart", raw);
  cases.back().model = "stable_neo_hookean";
  cases.push_back({"sudden_huge_force", "impulse: +100 m/s on the left ball mid-run"});
  cases.back().kick_at_half = 100;

  bool ok = true;
  std::printf("%-29s %-10s %6s %12s %8s  %s\n", "case", "outcome", "frames", "max energy",
              "contact", "expectation / diagnostic");
  for (const Case& c : cases) {
    const Outcome o = run_case(c, frames);
    std::printf("%-29s %-10s %6d %12.4g %8d  %s\n", c.name.c_str(), o.status.c_str(), o.frames,
                o.max_energy, o.contact_frames,
                o.message.empty() ? c.what.c_str() : o.message.c_str());
    ok = ok && o.status != "FAILED";
  }
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("faults", run, argc, argv);
}
