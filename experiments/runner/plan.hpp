#pragma once
/// Which stages a scene needs: a scene runs only the parts it needs.
#include <cstdint>
#include <limits>
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
  bool broad_phase = false;  ///< more than one candidate pair: cull by root spheres first
  bool response = false;     ///< penalty forces onto deformable objects
  bool exact_reference = false;
  bool vtu_output = false;
  /// Deepest sphere-tree level the queries can use (root = 0); the trees are
  /// cut below it at load, so deeper levels are never stored or updated.
  /// Bounded by collision.depth_cap (nodes at the cap are never split) and by
  /// the budget (see max_usable_level()); INT_MAX when neither bounds it.
  int max_tree_level = std::numeric_limits<int>::max();

  /// One line per stage, e.g. "bunny: fem (stvk, rk4)", for --dry-run.
  std::vector<std::string> describe(const Scene& scene) const;
};

/// Deepest level a query can use within the budget. A sphere of level L is
/// first used (tested, or reported untested when the budget runs out in the
/// middle of its parent's split) in the L-th split of its tree, and every
/// split tests at least 2 children, so at least 1 + 2 (L - 1) = 2L - 1 tests
/// come first, in any traversal mode. The time budget is converted at
/// kFastestTestSeconds, faster than any sphere test here (the FIFO traversal
/// measures 3-6 ns per test), so it cuts only budgets that cannot reach a
/// level on any machine. budget_tests < 0 and an infinite budget_seconds
/// mean no bound.
int max_usable_level(int64_t budget_tests, double budget_seconds);

/// Time per sphere test assumed by max_usable_level() (s).
inline constexpr double kFastestTestSeconds = 1e-9;

/// Decides the stages: FEM only for deformable objects; no collision
/// pipeline for a single object or between two non-moving objects; no sphere
/// update for static objects; no dense-mesh update unless the output or the
/// exact reference consumes the dense mesh; no tree level deeper than the
/// depth cap or the budget can reach.
StagePlan make_plan(const Scene& scene);

}  // namespace icd::runner
