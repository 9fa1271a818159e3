#pragma once
/// Which stages a simulation needs: a scene runs only the parts it needs.
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <icd/coupling/world_settings.hpp>

namespace icd::coupling {

/// Stages of one object.
struct ObjectPlan {
  bool fem = false;            ///< explicit FEM on the coarse mesh (deformable objects)
  bool kinematic = false;      ///< rigid motion with the initial velocity
  bool sphere_tree = false;    ///< load the tree (the object takes part in collisions)
  bool sphere_update = false;  ///< update the tree from the coarse nodes each frame
  bool dense_update = false;   ///< evaluate the rigid links (something consumes the dense mesh)
};

/// Why the sphere trees are cut below some level.
enum class TreeCut {
  None,      ///< every level is kept
  DepthCap,  ///< collision.query.depth_cap: nodes at the cap are never split
  TestBudget,  ///< collision.query.budget_tests cannot reach deeper levels
};

/// The stages of a whole simulation.
struct StagePlan {
  std::vector<ObjectPlan> objects;
  /// Object pairs whose collisions are detected (at least one moves).
  std::vector<std::pair<int, int>> pairs;
  bool broad_phase = false;  ///< more than one candidate pair: cull by root spheres first
  bool response = false;     ///< penalty forces onto deformable objects
  bool exact_reference = false;
  /// Deepest sphere-tree level the queries can use (root = 0), when
  /// tree_cut != None: the World cuts the trees below it at construction,
  /// so deeper levels are never stored or updated. INT_MAX otherwise.
  int max_tree_level = std::numeric_limits<int>::max();
  TreeCut tree_cut = TreeCut::None;

  /// One line per stage, e.g. "bunny: fem (stvk, rk4)", for --dry-run.
  std::vector<std::string> describe(std::span<const ObjectSetup> objects,
                                    const WorldSettings& settings) const;
};

/// Deepest level a query with a budget of `budget_tests` sphere tests can
/// use (-1: no bound, INT_MAX returned). A sphere of level L is first used
/// (tested, or reported untested when the budget runs out in the middle of
/// its parent's split) in the L-th split of its tree, and every split tests
/// at least 2 children, so at least 1 + 2 (L - 1) = 2L - 1 tests come first,
/// in any traversal mode. A time budget bounds no level: how many tests fit
/// in it depends on the machine.
int max_usable_level(int64_t budget_tests);

/// Decides the stages: FEM only for deformable objects; no collision
/// pipeline for a single object or between two non-moving objects; no sphere
/// update for static objects; no dense-mesh update unless the settings
/// consume the dense meshes; no tree level deeper than the depth cap or the
/// test budget can reach.
StagePlan make_plan(std::span<const ObjectSetup> objects, const WorldSettings& settings);

}  // namespace icd::coupling
