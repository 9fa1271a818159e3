#include <icd/coupling/stage_plan.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace icd::coupling {

int max_usable_level(int64_t budget_tests) {
  if (budget_tests < 0 || budget_tests >= 2 * 64) return std::numeric_limits<int>::max();
  // Largest L with 2L - 1 <= tests (L = 0: the root pair only).
  return static_cast<int>((budget_tests + 1) / 2);
}

StagePlan make_plan(std::span<const ObjectSetup> objects, const WorldSettings& settings) {
  StagePlan plan;
  const int n = static_cast<int>(objects.size());
  plan.objects.resize(n);
  for (int i = 0; i < n; ++i) {
    plan.objects[i].fem = objects[i].kind == ObjectKind::Deformable;
    plan.objects[i].kinematic = objects[i].kind == ObjectKind::Rigid;
  }
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const bool moves_i = objects[i].kind != ObjectKind::Static;
      const bool moves_j = objects[j].kind != ObjectKind::Static;
      if ((moves_i || moves_j) && objects[i].sphere_collisions && objects[j].sphere_collisions)
        plan.pairs.emplace_back(i, j);
    }
  for (const auto& [i, j] : plan.pairs)
    for (int k : {i, j}) {
      plan.objects[k].sphere_tree = true;
      plan.objects[k].sphere_update = objects[k].kind != ObjectKind::Static;
      plan.response |= objects[k].kind == ObjectKind::Deformable;
    }
  plan.broad_phase = plan.pairs.size() > 1;
  if (!plan.pairs.empty()) {
    const collision::CollisionRequest& q = settings.collision.query;
    const int by_budget = max_usable_level(q.budget_tests);
    if (by_budget != std::numeric_limits<int>::max()) {
      plan.max_tree_level = by_budget;
      plan.tree_cut = TreeCut::TestBudget;
    }
    if (q.depth_cap < plan.max_tree_level) {
      plan.max_tree_level = q.depth_cap;
      plan.tree_cut = TreeCut::DepthCap;
    }
  }
  plan.exact_reference = settings.exact_reference && !plan.pairs.empty();
  for (int i = 0; i < n; ++i) {
    const bool moves = objects[i].kind != ObjectKind::Static;
    plan.objects[i].dense_update =
        moves && (settings.dense_meshes || (plan.exact_reference && plan.objects[i].sphere_tree));
  }
  return plan;
}

std::vector<std::string> StagePlan::describe(std::span<const ObjectSetup> setups,
                                             const WorldSettings& settings) const {
  std::vector<std::string> lines;
  for (size_t i = 0; i < objects.size(); ++i) {
    const ObjectSetup& o = setups[i];
    const ObjectPlan& p = objects[i];
    std::ostringstream s;
    s << o.name << ": load";
    if (p.fem)
      s << ", fem (" << fem::to_string(o.material.model) << ", " << fem::to_string(o.integrator)
        << ")";
    if (p.kinematic) s << ", rigid motion";
    if (!p.fem && !p.kinematic) s << ", static";
    if (p.sphere_tree) s << ", sphere tree";
    if (p.sphere_update) s << ", sphere update";
    if (p.dense_update) s << ", rigid links (dense mesh)";
    lines.push_back(s.str());
  }
  if (pairs.empty()) {
    lines.emplace_back("collision: none");
  } else {
    if (broad_phase) lines.emplace_back("broad phase: root-sphere culling");
    const collision::CollisionRequest& q = settings.collision.query;
    switch (tree_cut) {
      case TreeCut::None:
        if (q.budget_tests >= 0)
          lines.push_back("sphere trees: every level kept (a budget of " +
                          std::to_string(q.budget_tests) + " tests cuts no level)");
        else if (std::isfinite(q.budget_seconds))
          lines.emplace_back(
              "sphere trees: every level kept (a time budget cuts no level: how deep a query "
              "gets depends on the machine and the pair)");
        else
          lines.emplace_back("sphere trees: every level kept (no budget, no depth cap)");
        break;
      case TreeCut::DepthCap:
        lines.push_back("sphere trees: levels 0.." + std::to_string(max_tree_level) +
                        " only (collision.depth_cap; deeper levels not loaded, not updated)");
        break;
      case TreeCut::TestBudget:
        lines.push_back("sphere trees: levels 0.." + std::to_string(max_tree_level) +
                        " only (a level-L sphere needs 2L - 1 tests first, beyond the budget of " +
                        std::to_string(q.budget_tests) +
                        " tests; deeper levels not loaded, not updated)");
        break;
    }
    for (const auto& [i, j] : pairs)
      lines.push_back("collision: " + setups[i].name + " <-> " + setups[j].name);
  }
  lines.emplace_back(std::string("response: ") + (response ? "penalty forces" : "none"));
  if (exact_reference) lines.emplace_back("exact reference: dense triangle intersections");
  return lines;
}

}  // namespace icd::coupling
