#pragma once

#include <string>

#include "experiments/runner/scene.hpp"

namespace icd::runner {

/// Two identical soft spheres (radius 0.1 m, E = 5e5 Pa) 0.24 m apart, meeting
/// head-on along x at 0.6 m/s each; 30 frames at 60 Hz. `collision` is spliced
/// into the scene's collision block (JSON members without braces); the penalty
/// stiffness is 2000 N/m unless `collision` sets it.
inline Scene head_on_scene(const std::string& collision) {
  const std::string text =
      R"({
    "frames": 30, "frame_rate": 60,
    "objects": [
      {"name": "left", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 2, "cells": 5},
       "position": [-0.12, 0, 0], "velocity": [0.6, 0, 0],
       "material": {"young": 5e5, "poisson": 0.3, "density": 1000}, "preprocess": {"tree_depth": 3}},
      {"name": "right", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 2, "cells": 5},
       "position": [0.12, 0, 0], "velocity": [-0.6, 0, 0],
       "material": {"young": 5e5, "poisson": 0.3, "density": 1000}, "preprocess": {"tree_depth": 3}}
    ],
    "collision": {)" +
      (collision.find("stiffness") == std::string::npos ? std::string(R"("stiffness": 2000, )")
                                                        : std::string()) +
      collision + R"(},
    "output": {"csv": false}
  })";
  return parse_scene(parse_json(text, "head_on"), "head_on", ".");
}

}  // namespace icd::runner
