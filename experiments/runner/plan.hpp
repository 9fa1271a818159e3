#pragma once
/// Which stages a scene needs: a scene runs only the parts it needs.
#include <string>
#include <utility>
#include <vector>

#include "experiments/runner/scene.hpp"

namespace icd::runner {

/// Stages of one object.
struct ObjectPlan {
  bool fem = false;            ///< explicit FEM on the coarse mesh (deformable objects)
  bool kinematic = false;      ///< rigid motion with the initial velocity
  bool sphere_tree = false;    ///< load the tree (the object takes part in collisions)
  bool sphere_update = false;  ///< update the tree from the coarse nodes each frame
  bool dense_update = false;   ///< evaluate the rigid links (something consumes the dense mesh)
};

/// The stages of a whole scene.
struct StagePlan {
  std::vector<ObjectPlan> objects;
  /// Object pairs whose collisions are detected (at least one moves).
  std::vector<std::pair<int, int>> pairs;
  bool broad_phase = false;   ///< more than one candidate pair: cull by root spheres first
  bool response = false;      ///< penalty forces onto deformable objects
  bool exact_reference = false;
  bool vtu_output = false;

  /// One line per stage, e.g. "bunny: fem (stvk, rk4)", for --dry-run.
  std::vector<std::string> describe(const Scene& scene) const;
};

/// Decides the stages: FEM only for deformable objects; no collision
/// pipeline for a single object or between two non-moving objects; no sphere
/// update for static objects; no dense-mesh update unless the output or the
/// exact reference consumes the dense mesh.
StagePlan make_plan(const Scene& scene);

}  // namespace icd::runner
