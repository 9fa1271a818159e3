// The central guarantee (issue 6): at any budget, every point where the two
// dense surfaces truly intersect lies in both spheres of some reported pair
// (a colliding leaf pair or an untested pair). Oracle: exact triangle-triangle
// intersection of the dense meshes (AABB tree, itself checked against brute force).
#include <gtest/gtest.h>

#include <unordered_set>

#include <Eigen/Geometry>

#include <icd/collision/aabb_tree.hpp>
#include <icd/collision/node_association.hpp>
#include <icd/collision/sphere_update.hpp>
#include <icd/collision/triangle_intersection.hpp>
#include "contact_oracle.hpp"
#include "tree_fixtures.hpp"

namespace icd::collision {
namespace {

using namespace icd::collision::testing;

TEST(Conservative, OverlappingIcospheresAtRest) {
  const SurfaceMesh a = make_icosphere(3);
  const SurfaceMesh b = translated(make_icosphere(3, 0.8), {1.2, 0.3, -0.2});
  OctreeTreeOptions o;
  o.levels = 4;
  check_all_budgets(build_octree_tree(a.V, a.F, o), build_octree_tree(b.V, b.F, o),
                    contact_points(a.V, a.F, b.V, b.F));
}

TEST(Conservative, OracleDetectsTreesThatStopCoveringTheSurface) {
  // Mutation check of the oracle itself: with the leaf spheres of one tree
  // shrunk, some true contact point must fall outside every reported pair.
  const SurfaceMesh a = make_icosphere(3);
  const SurfaceMesh b = translated(make_icosphere(3, 0.8), {1.2, 0.3, -0.2});
  OctreeTreeOptions o;
  o.levels = 4;
  SphereTree ta = build_octree_tree(a.V, a.F, o);
  const SphereTree tb = build_octree_tree(b.V, b.F, o);
  for (int i = 0; i < ta.num_nodes(); ++i)
    if (ta.is_leaf(i)) ta.spheres[i].r *= 0.5;
  const CollisionResult res = collide(ta, tb, CollisionRequest{});
  int lost = 0;
  for (const auto& p : contact_points(a.V, a.F, b.V, b.F)) {
    bool covered = false;
    for (const NodePair& q : res.colliding)
      covered = covered || ((p - ta.spheres[q.a].center()).norm() <= ta.spheres[q.a].r &&
                            (p - tb.spheres[q.b].center()).norm() <= tb.spheres[q.b].r);
    lost += !covered;
  }
  EXPECT_GT(lost, 0);
}

TEST(Conservative, InterlockedToriAtRest) {
  const SurfaceMesh a = make_torus(1.0, 0.3, 32, 12);
  SurfaceMesh b = make_torus(1.0, 0.3, 32, 12);
  // Rotate b by 90 degrees about x and shift it so the tori interpenetrate.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  b.V = (b.V * R.transpose()).eval();
  b.V.rowwise() += Eigen::RowVector3d(1.9, 0.1, 0.05);  // b passes through a's tube
  OctreeTreeOptions o;
  o.levels = 4;
  check_all_budgets(build_octree_tree(a.V, a.F, o), build_octree_tree(b.V, b.F, o),
                    contact_points(a.V, a.F, b.V, b.F));
}

// A dense mesh steered by coarse nodes through convex weights (as linear
// interpolation in a coarse mesh does), deformed by a smooth field.
struct Deformable {
  SurfaceMesh dense;
  MatX3d coarse;
  std::vector<int32_t> off{0}, nodes;
  std::vector<double> w;
  SphereTree tree;
};

Deformable make_deformable(const SurfaceMesh& dense, const MatX3d& coarse) {
  Deformable d{dense, coarse, {0}, {}, {}, {}};
  for (int v = 0; v < dense.V.rows(); ++v) {
    std::vector<std::pair<double, int>> dist;
    for (int j = 0; j < coarse.rows(); ++j)
      dist.push_back({(coarse.row(j) - dense.V.row(v)).norm(), j});
    std::sort(dist.begin(), dist.end());
    double sum = 0;
    for (int k = 0; k < 4; ++k) sum += 1 / (dist[k].first + 1e-2);
    for (int k = 0; k < 4; ++k) {
      d.nodes.push_back(dist[k].second);
      d.w.push_back(1 / (dist[k].first + 1e-2) / sum);
    }
    d.off.push_back(static_cast<int32_t>(d.nodes.size()));
  }
  OctreeTreeOptions o;
  o.levels = 4;
  d.tree = build_octree_tree(dense.V, dense.F, o);
  associate_steering_nodes(d.tree, coarse, dense.V, dense.F, d.off, d.nodes);
  return d;
}

MatX3d deform_coarse(const MatX3d& X, double amp, double phase, const Eigen::Vector3d& shift) {
  MatX3d x = X;
  for (int i = 0; i < X.rows(); ++i) {
    const Eigen::Vector3d p = X.row(i).transpose();
    x.row(i) = (p +
                amp * Eigen::Vector3d(std::sin(2 * p.y() + phase),
                                      0.5 * std::cos(3 * p.z() - phase), std::sin(p.x() + p.y())) +
                shift)
                   .transpose();
  }
  return x;
}

MatX3d dense_positions(const Deformable& d, const MatX3d& x) {
  MatX3d V = d.dense.V;
  for (int v = 0; v < V.rows(); ++v)
    for (int k = d.off[v]; k < d.off[v + 1]; ++k)
      V.row(v) += d.w[k] * (x.row(d.nodes[k]) - d.coarse.row(d.nodes[k]));
  return V;
}

TEST(Conservative, DeformedIcosphereAndTorusWithConservativeUpdate) {
  Deformable a = make_deformable(make_icosphere(3), make_icosphere(1, 1.0).V);
  Deformable b = make_deformable(make_torus(1.0, 0.3, 32, 12), make_torus(1.0, 0.3, 8, 4).V);
  SphereUpdateOptions o;
  o.mode = SphereUpdateMode::DisplacementBound;
  for (int frame = 0; frame < 2; ++frame) {
    const MatX3d xa = deform_coarse(a.coarse, 0.15, 0.7 * frame, {0, 0, 0});
    const MatX3d xb = deform_coarse(b.coarse, 0.1, -0.5 * frame, {0.9, 0.2, 0.1});
    update_spheres(a.tree, a.coarse, xa, o);
    update_spheres(b.tree, b.coarse, xb, o);
    const MatX3d Va = dense_positions(a, xa), Vb = dense_positions(b, xb);
    check_all_budgets(a.tree, b.tree, contact_points(Va, a.dense.F, Vb, b.dense.F));
  }
}

}  // namespace
}  // namespace icd::collision
