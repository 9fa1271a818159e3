#include "experiments/studies/reliability/soak_scene.hpp"

#include <limits>
#include <sstream>

#include "experiments/runner/scene.hpp"

namespace icd::reliability {

runner::Scene make_contact_box_scene(const ContactBoxOptions& o) {
  std::ostringstream s;
  s.precision(17);
  s << R"({"name": "contact_box", "frames": 100, "frame_rate": 60, "objects": [)"
    << R"({"name": "ball", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 2, )"
    << R"("cells": )" << o.cells << R"(}, "position": [0, 0, 0], "velocity": [)" << o.speed
    << R"(, 0, 0], "material": {"model": "stvk", "young": 2e5, "poisson": 0.3, "density": 500},)"
    << R"( "integrator": ")" << o.integrator << R"(", "preprocess": {"tree_depth": 3}},)"
    << R"({"name": "left", "primitive": {"type": "box", "extent": [0.1, 0.6, 0.6], "cells": 2},)"
    << R"( "position": [-0.3, 0, 0], "kind": "static", "collider": "spheres", "preprocess": {"tree_depth": 2}},)"
    << R"({"name": "right", "primitive": {"type": "box", "extent": [0.1, 0.6, 0.6], "cells": 2},)"
    << R"( "position": [0.3, 0, 0], "kind": "static", "collider": "spheres", "preprocess": {"tree_depth": 2}}],)"
    << R"("collision": {"budget_tests": )" << o.budget_tests << R"(, "mode": "fifo", "stiffness": )"
    << o.stiffness << R"(, "layered": true}, "output": {"vtu_every": 0}})";
  return runner::parse_scene(runner::parse_json(s.str(), "contact_box"), "contact_box", ".");
}

void use_test_budget(runner::Scene& scene, int64_t budget_tests) {
  scene.world.collision.query.budget_tests = budget_tests;
  scene.world.collision.query.budget_seconds = std::numeric_limits<double>::infinity();
}

}  // namespace icd::reliability
