// Our sphere-tree update and traversal vs the Flexible Collision Library on
// two overlapping deforming dragons and two overlapping deforming bunnies
// (issue 6). Same run, one thread. Per frame both objects are deformed by a
// smooth field: our trees are updated from the coarse nodes (paper 4.4), FCL's
// BVHModel<AABBd> over the dense triangles is refitted (beginReplaceModel /
// replaceSubModel / endReplaceModel(refit, bottom-up)); then our full
// (uninterrupted) traversal to the leaf spheres vs fcl::collide.
// Each operation is timed 3 times per frame (min kept, the machine is
// shared); the table gives medians over the frames and their ratios.
//
// Usage: icd_collision_vs_fcl [--frames N] [--levels L]
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fcl/fcl.h>

#include <icd/collision/aabb_tree.hpp>
#include <icd/collision/sphere_update.hpp>
#include <icd/collision/traversal.hpp>
#include "experiments/studies/collision/workloads.hpp"
#include "experiments/common/cli.hpp"

using namespace icd::collision;
using namespace icd::collision::experiments;
using Clock = std::chrono::steady_clock;
using Model = fcl::BVHModel<fcl::AABBd>;

namespace {

template <class F>
double time_min3(F&& f) {
  double best = 1e30;
  for (int r = 0; r < 3; ++r) {
    const auto t0 = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  return best;
}

std::vector<fcl::Vector3d> to_points(const icd::MatX3d& V) {
  std::vector<fcl::Vector3d> p(V.rows());
  for (int i = 0; i < V.rows(); ++i) p[i] = V.row(i).transpose();
  return p;
}

std::shared_ptr<Model> make_model(const icd::SurfaceMesh& m) {
  auto model = std::make_shared<Model>();
  std::vector<fcl::Triangle> tris(m.F.rows());
  for (int f = 0; f < m.F.rows(); ++f) tris[f] = fcl::Triangle(m.F(f, 0), m.F(f, 1), m.F(f, 2));
  model->beginModel(static_cast<int>(m.F.rows()), static_cast<int>(m.V.rows()));
  model->addSubModel(to_points(m.V), tris);
  model->endModel();
  return model;
}

void run_scene(const std::string& file, int frames, int levels) {
  Object a = load_object(file, {0, 0, 0}, levels);
  Object b = load_object(file, {0.45, 0.15, 0.05}, levels);
  std::printf(
      "\n== %s: %ld vertices, %ld triangles per copy; octree sphere trees (%d levels): %d spheres "
      "each "
      "(%d leaves); %ld coarse nodes\n",
      file.c_str(), (long)a.dense.V.rows(), (long)a.dense.F.rows(), levels, a.tree.num_nodes(),
      a.tree.level_offset.back() - a.tree.level_offset[a.tree.num_levels() - 1],
      (long)a.coarse_rest.rows());
  auto ma = make_model(a.dense), mb = make_model(b.dense);
  fcl::CollisionObjectd oa(ma, fcl::Transform3d::Identity()), ob(mb, fcl::Transform3d::Identity());

  std::vector<double> t_upd, t_upd_cons, t_refit, t_fast, t_literal, t_fcl_first, t_fcl_all, t_aabb;
  std::vector<double> tests, leaf_pairs, fcl_contacts, tri_pairs;
  SphereUpdateOptions paper, cons;
  cons.mode = SphereUpdateMode::DisplacementBound;
  AabbTree ra(a.dense.V, a.dense.F), rb(b.dense.V, b.dense.F);
  CollisionResult res;
  for (int frame = 0; frame < frames; ++frame) {
    const double t = 0.2 * frame;
    const icd::MatX3d xa = deform(a.coarse_rest, 0.05, t),
                      xb = deform(b.coarse_rest, 0.05, t + 1.0);
    const icd::MatX3d Va = deform(a.dense.V, 0.05, t), Vb = deform(b.dense.V, 0.05, t + 1.0);
    const auto pa = to_points(Va), pb = to_points(Vb);

    t_upd_cons.push_back(time_min3([&] {
      update_spheres(a.tree, a.coarse_rest, xa, cons);
      update_spheres(b.tree, b.coarse_rest, xb, cons);
    }));
    t_upd.push_back(time_min3([&] {
      update_spheres(a.tree, a.coarse_rest, xa, paper);
      update_spheres(b.tree, b.coarse_rest, xb, paper);
    }));
    t_refit.push_back(time_min3([&] {
      ma->beginReplaceModel();
      ma->replaceSubModel(pa);
      ma->endReplaceModel(true, true);
      mb->beginReplaceModel();
      mb->replaceSubModel(pb);
      mb->endReplaceModel(true, true);
      oa.computeAABB();
      ob.computeAABB();
    }));
    t_fast.push_back(time_min3([&] { collide(a.tree, b.tree, CollisionRequest{}, res); }));
    tests.push_back(static_cast<double>(res.tests));
    leaf_pairs.push_back(static_cast<double>(res.colliding.size()));
    t_literal.push_back(time_min3([&] {
      collide(a.tree, b.tree,
              CollisionRequest::paper_reference(std::numeric_limits<double>::infinity()), res);
    }));
    t_fcl_first.push_back(time_min3([&] {
      fcl::CollisionRequestd req(1, false);
      fcl::CollisionResultd out;
      fcl::collide(&oa, &ob, req, out);
    }));
    t_fcl_all.push_back(time_min3([&] {
      fcl::CollisionRequestd req(1000000, false);
      fcl::CollisionResultd out;
      fcl::collide(&oa, &ob, req, out);
      fcl_contacts.push_back(static_cast<double>(out.numContacts()));
    }));
    std::size_t np = 0;
    t_aabb.push_back(time_min3([&] {
      ra.refit(Va, a.dense.F);
      rb.refit(Vb, b.dense.F);
      np = intersecting_triangle_pairs(ra, Va, a.dense.F, rb, Vb, b.dense.F).size();
    }));
    tri_pairs.push_back(static_cast<double>(np));
  }
  const double upd = median(t_upd), refit = median(t_refit), fast = median(t_fast),
               all = median(t_fcl_all);
  const int spheres = a.tree.num_nodes() + b.tree.num_nodes();
  std::printf("%-52s %12s %10s\n", "operation (both objects), median over frames", "time", "ratio");
  std::printf("%-52s %10.1f us %10s\n", "ours: sphere update, paper ratio", 1e6 * upd, "1");
  std::printf("%-52s %10.1f us %10.2f\n", "ours: sphere update, conservative bound",
              1e6 * median(t_upd_cons), median(t_upd_cons) / upd);
  std::printf("%-52s %10.1f us %10.1f  (FCL / ours)\n",
              "FCL: refit BVHModel<AABBd> (replace + bottom-up)", 1e6 * refit, refit / upd);
  std::printf("  update cost per sphere: %.1f ns\n", 1e9 * upd / spheres);
  std::printf("%-52s %10.1f us %10s  (%.0f sphere tests, %.0f leaf pairs)\n",
              "ours: full traversal, fast path", 1e6 * fast, "1", median(tests),
              median(leaf_pairs));
  std::printf("%-52s %10.1f us %10.2f\n", "ours: full traversal, literal Fig. 7",
              1e6 * median(t_literal), median(t_literal) / fast);
  std::printf("%-52s %10.1f us %10.1f  (FCL / ours)\n", "FCL: collide, first contact",
              1e6 * median(t_fcl_first), median(t_fcl_first) / fast);
  std::printf("%-52s %10.1f us %10.1f  (FCL / ours; %.0f contacts)\n", "FCL: collide, all contacts",
              1e6 * all, all / fast, median(fcl_contacts));
  std::printf("%-52s %10.1f us %10.1f  (%.0f intersecting triangle pairs)\n",
              "ours: exact reference (AABB refit + tri-tri)", 1e6 * median(t_aabb),
              median(t_aabb) / fast, median(tri_pairs));
  int agree = 0;
  for (std::size_t k = 0; k < tri_pairs.size(); ++k) agree += tri_pairs[k] == fcl_contacts[3 * k];
  std::printf(
      "  exact reference and FCL report the same number of intersecting triangle pairs in %d of "
      "%zu frames\n",
      agree, tri_pairs.size());
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 20, levels = 4;
  icd::experiments::Cli cli("icd_collision_vs_fcl");
  cli.integer("--frames", frames, "N", "frames (default 20)", 1)
      .integer("--levels", levels, "L", "sphere-tree levels (default 4)", 1);
  if (const auto status = cli.parse(argc, argv)) return *status;
  try {
    run_scene("ChineseDragon-10kv.off", frames, levels);
    run_scene("bunny00.off", frames, levels);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
