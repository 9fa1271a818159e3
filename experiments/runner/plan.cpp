#include "experiments/runner/plan.hpp"

#include <sstream>

namespace icd::runner {

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
  plan.vtu_output = scene.output.vtu_every > 0;
  plan.exact_reference = scene.output.exact_reference && !plan.pairs.empty();
  for (int i = 0; i < n; ++i) {
    const bool moves = scene.objects[i].kind != ObjectKind::Static;
    plan.objects[i].dense_update =
        moves && ((plan.vtu_output && scene.output.dense) ||
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
