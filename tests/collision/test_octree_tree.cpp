#include <gtest/gtest.h>

#include <random>
#include <set>

#include <icd/collision/node_association.hpp>
#include <icd/collision/octree_tree.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::collision {
namespace {

bool inside(const Sphere& s, const Eigen::Vector3d& p, double tol = 1e-12) {
  return (p - s.center()).norm() <= s.r * (1 + tol) + tol;
}

// Is there a root-to-leaf chain of spheres that all contain p? (What pruning
// on non-overlapping parents needs.)
bool chain_covers(const SphereTree& t, int node, const Eigen::Vector3d& p) {
  if (!inside(t.spheres[node], p)) return false;
  if (t.is_leaf(node)) return true;
  for (int c = 0; c < t.child_count[node]; ++c)
    if (chain_covers(t, t.first_child[node] + c, p)) return true;
  return false;
}

std::vector<Eigen::Vector3d> surface_samples(const SurfaceMesh& m, int per_face, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Vector3d> pts;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < per_face; ++k) {
      double a = u(rng), b = u(rng);
      if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
      }
      // Include edges and corners explicitly every few samples.
      if (k == 0) {
        a = 0;
        b = 0;
      }
      if (k == 1) {
        a = 0.5;
        b = 0;
      }
      pts.push_back((1 - a - b) * m.V.row(m.F(f, 0)).transpose() +
                    a * m.V.row(m.F(f, 1)).transpose() + b * m.V.row(m.F(f, 2)).transpose());
    }
  return pts;
}

TEST(OctreeTree, EveryLevelAndEveryChainCoversTheSurface) {
  std::vector<SurfaceMesh> meshes = {make_icosphere(3),
                                     make_box_surface({-1, -0.5, 0}, {2, 0.5, 0.25}),
                                     make_torus(1.0, 0.3, 24, 12)};
  for (const SurfaceMesh& m : meshes) {
    OctreeTreeOptions o;
    o.levels = 4;
    const SphereTree t = build_octree_tree(m.V, m.F, o);
    ASSERT_NO_THROW(validate(t));
    EXPECT_EQ(t.num_levels(), 4);
    const auto pts = surface_samples(m, 6, 1);
    for (const auto& p : pts) {
      ASSERT_TRUE(chain_covers(t, 0, p)) << p.transpose();
      for (int l = 0; l < t.num_levels(); ++l) {
        bool covered = false;
        for (int i = t.level_offset[l]; i < t.level_offset[l + 1] && !covered; ++i)
          covered = inside(t.spheres[i], p);
        ASSERT_TRUE(covered) << "level " << l;
      }
    }
    // Leaf spheres are no larger than the circumsphere of a leaf cell.
    const Eigen::Vector3d ext = m.V.colwise().maxCoeff() - m.V.colwise().minCoeff();
    const double leaf_side = ext.maxCoeff() * (1 + 1e-6) / 8.0;
    for (int i = t.level_offset[3]; i < t.num_nodes(); ++i)
      EXPECT_LE(t.spheres[i].r, 0.5 * std::sqrt(3.0) * leaf_side * (1 + 1e-6));
  }
}

TEST(OctreeTree, ChildCountsAndDeterminism) {
  const SurfaceMesh m = make_icosphere(2);
  OctreeTreeOptions o;
  o.levels = 3;
  const SphereTree a = build_octree_tree(m.V, m.F, o), b = build_octree_tree(m.V, m.F, o);
  ASSERT_EQ(a.num_nodes(), b.num_nodes());
  for (int i = 0; i < a.num_nodes(); ++i) EXPECT_EQ(a.spheres[i].r, b.spheres[i].r);
  for (int i = 0; i < a.num_nodes(); ++i) EXPECT_LE(a.child_count[i], 8);
  // An icosphere meets all 8 octants of its bounding cube.
  EXPECT_EQ(a.child_count[0], 8);
}

TEST(OctreeTree, RejectsBadInput) {
  const SurfaceMesh m = make_icosphere(1);
  OctreeTreeOptions o;
  o.levels = 0;
  EXPECT_THROW(build_octree_tree(m.V, m.F, o), ParameterError);
  MatX3i F = m.F;
  F(3, 1) = 1000;
  EXPECT_THROW(build_octree_tree(m.V, F, {}), InputError);
  MatX3d V = m.V;
  V(2, 0) = std::nan("");
  EXPECT_THROW(build_octree_tree(V, m.F, {}), InputError);
}

TEST(NodeAssociation, NearestAndInsideAgainstBruteForce) {
  const SurfaceMesh m = make_icosphere(2);
  const SphereTree t0 = build_octree_tree(m.V, m.F, {});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  MatX3d P(60, 3);
  for (int i = 0; i < P.rows(); ++i) P.row(i) << u(rng), u(rng), u(rng);
  SphereTree t = t0;
  NodeAssociationOptions o;
  o.k_nearest = 3;
  o.max_nodes = 20;
  associate_nearest_nodes(t, P, o);
  ASSERT_NO_THROW(validate(t));
  for (int i = 0; i < t.num_nodes(); ++i) {
    const Sphere& s = t.rest_spheres[i];
    std::vector<double> d(P.rows());
    int n_inside = 0;
    for (int j = 0; j < P.rows(); ++j) {
      d[j] = (P.row(j).transpose() - s.center()).norm();
      n_inside += d[j] <= s.r;
    }
    const int expected = std::min(o.max_nodes, std::max(o.k_nearest, n_inside));
    ASSERT_EQ(t.assoc_offset[i + 1] - t.assoc_offset[i], expected) << "node " << i;
    std::vector<double> sorted = d;
    std::sort(sorted.begin(), sorted.end());
    double worst = 0;
    for (int k = t.assoc_offset[i]; k < t.assoc_offset[i + 1]; ++k) {
      EXPECT_NEAR(t.assoc_rest_dist[k], d[t.assoc_nodes[k]], 1e-12);
      worst = std::max(worst, t.assoc_rest_dist[k]);
    }
    // The chosen set is exactly the `expected` nearest nodes.
    EXPECT_NEAR(worst, sorted[expected - 1], 1e-12);
  }
}

TEST(NodeAssociation, SteeringNodesOfEveryTriangleMeetingTheSphere) {
  const SurfaceMesh m = make_icosphere(2);
  SphereTree t = build_octree_tree(m.V, m.F, {});
  // Coarse nodes: 12 icosahedron vertices; each dense vertex steered by its 2 nearest.
  const SurfaceMesh coarse = make_icosphere(0);
  std::vector<int32_t> off{0}, nodes;
  for (int v = 0; v < m.V.rows(); ++v) {
    std::vector<std::pair<double, int>> d;
    for (int j = 0; j < coarse.V.rows(); ++j)
      d.push_back({(coarse.V.row(j) - m.V.row(v)).norm(), j});
    std::sort(d.begin(), d.end());
    nodes.push_back(d[0].second);
    nodes.push_back(d[1].second);
    off.push_back(static_cast<int32_t>(nodes.size()));
  }
  associate_steering_nodes(t, coarse.V, m.V, m.F, off, nodes, 0);
  ASSERT_NO_THROW(validate(t));
  // Oracle: sample each triangle densely; if a sample lies in the sphere, the
  // steering nodes of the triangle's vertices must all be associated.
  const auto pts_per_face = 15;
  for (int i = 0; i < t.num_nodes(); ++i) {
    std::set<int> got(t.assoc_nodes.begin() + t.assoc_offset[i],
                      t.assoc_nodes.begin() + t.assoc_offset[i + 1]);
    for (int f = 0; f < m.F.rows(); ++f) {
      bool meets = false;
      for (int a = 0; a <= pts_per_face && !meets; ++a)
        for (int b = 0; a + b <= pts_per_face && !meets; ++b) {
          const double wa = double(a) / pts_per_face, wb = double(b) / pts_per_face;
          const Eigen::Vector3d p = (1 - wa - wb) * m.V.row(m.F(f, 0)).transpose() +
                                    wa * m.V.row(m.F(f, 1)).transpose() +
                                    wb * m.V.row(m.F(f, 2)).transpose();
          meets = (p - t.rest_spheres[i].center()).norm() <= t.rest_spheres[i].r;
        }
      if (!meets) continue;
      for (int k = 0; k < 3; ++k)
        for (int j = off[m.F(f, k)]; j < off[m.F(f, k) + 1]; ++j)
          ASSERT_TRUE(got.count(nodes[j])) << "sphere " << i;
    }
  }
}

}  // namespace
}  // namespace icd::collision
