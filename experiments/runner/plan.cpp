#include "experiments/runner/plan.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace icd::runner {

int max_usable_level(int64_t budget_tests, double budget_seconds) {
  double tests = std::numeric_limits<double>::infinity();
  if (budget_tests >= 0) tests = static_cast<double>(budget_tests);
  if (std::isfinite(budget_seconds)) tests = std::min(tests, budget_seconds / kFastestTestSeconds);
  if (!std::isfinite(tests) || tests >= 2.0 * 64) return std::numeric_limits<int>::max();
  // Largest L with 2L - 1 <= tests (L = 0: the root pair only).
  return static_cast<int>(std::floor((tests + 1) / 2));
}

StagePlan make_plan(const Scene& scene) {
  StagePlan plan;
  const int n = static_cast<int>(scene.objects.size());
  plan.objects.resize(n);
  for (int i = 0; i < n; ++i) {
    plan.objects[i].fem = scene.objects[i].kind == ObjectKind::Deformable;
    plan.objects[i].kinematic = scene.objects[i].kind == ObjectKind::Rigid;
  }
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const bool moves_i = scene.objects[i].kind != ObjectKind::Static;
      const bool moves_j = scene.objects[j].kind != ObjectKind::Static;
      if (moves_i || moves_j) plan.pairs.emplace_back(i, j);
    }
  for (const auto& [i, j] : plan.pairs)
    for (int k : {i, j}) {
      plan.objects[k].sphere_tree = true;
      plan.objects[k].sphere_update = scene.objects[k].kind != ObjectKind::Static;
      plan.response |= scene.objects[k].kind == ObjectKind::Deformable;
    }
  plan.broad_phase = plan.pairs.size() > 1;
  if (!plan.pairs.empty()) {
    const CollisionSpec& c = scene.collision;
    plan.max_tree_level = max_usable_level(c.budget_tests, c.budget_seconds);
    if (c.depth_cap >= 0) plan.max_tree_level = std::min(plan.max_tree_level, c.depth_cap);
  }
  plan.vtu_output = scene.output.vtu_every > 0;
  plan.exact_reference = scene.output.exact_reference && !plan.pairs.empty();
  for (int i = 0; i < n; ++i) {
    const bool moves = scene.objects[i].kind != ObjectKind::Static;
    plan.objects[i].dense_update = moves && ((plan.vtu_output && scene.output.dense) ||
                                             (plan.exact_reference && plan.objects[i].sphere_tree));
  }
  return plan;
}

std::vector<std::string> StagePlan::describe(const Scene& scene) const {
  std::vector<std::string> lines;
  for (size_t i = 0; i < objects.size(); ++i) {
    const ObjectSpec& o = scene.objects[i];
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
    if (max_tree_level == std::numeric_limits<int>::max())
      lines.emplace_back("sphere trees: every level (the budget and depth cap reach the leaves)");
    else
      lines.push_back("sphere trees: levels 0.." + std::to_string(max_tree_level) +
                      " only (deeper levels are beyond the " +
                      (scene.collision.depth_cap == max_tree_level ? "depth cap" : "budget") +
                      "; not loaded, not updated)");
    for (const auto& [i, j] : pairs)
      lines.push_back("collision: " + scene.objects[i].name + " <-> " + scene.objects[j].name);
  }
  lines.emplace_back(std::string("response: ") + (response ? "penalty forces" : "none"));
  if (exact_reference) lines.emplace_back("exact reference: dense triangle intersections");
  lines.emplace_back(std::string("output: ") + (scene.output.csv ? "frames.csv" : "no csv") +
                     (vtu_output ? ", VTU/PVD series" : ""));
  return lines;
}

}  // namespace icd::runner
