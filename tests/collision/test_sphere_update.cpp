#include <gtest/gtest.h>

#include <random>

#include <Eigen/Geometry>

#include <icd/collision/coverage.hpp>
#include <icd/collision/node_association.hpp>
#include <icd/collision/octree_tree.hpp>
#include <icd/collision/sphere_update.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::collision {
namespace {

// A dense surface steered by coarse nodes through convex weights: every dense
// vertex follows its 3 nearest coarse nodes with positive weights summing to 1.
struct Steered {
  SurfaceMesh dense;
  MatX3d coarse;
  std::vector<int32_t> off{0}, nodes;
  std::vector<double> weights;

  MatX3d deform(const MatX3d& coarse_now) const {
    MatX3d V = dense.V;
    for (int v = 0; v < V.rows(); ++v)
      for (int k = off[v]; k < off[v + 1]; ++k)
        V.row(v) += weights[k] * (coarse_now.row(nodes[k]) - coarse.row(nodes[k]));
    return V;
  }
};

Steered make_steered(const SurfaceMesh& dense, const SurfaceMesh& coarse_surface) {
  Steered s;
  s.dense = dense;
  s.coarse = coarse_surface.V;
  for (int v = 0; v < dense.V.rows(); ++v) {
    std::vector<std::pair<double, int>> d;
    for (int j = 0; j < s.coarse.rows(); ++j)
      d.push_back({(s.coarse.row(j) - dense.V.row(v)).norm(), j});
    std::sort(d.begin(), d.end());
    double sum = 0;
    for (int k = 0; k < 3; ++k) sum += 1.0 / (d[k].first + 1e-3);
    for (int k = 0; k < 3; ++k) {
      s.nodes.push_back(d[k].second);
      s.weights.push_back(1.0 / (d[k].first + 1e-3) / sum);
    }
    s.off.push_back(static_cast<int32_t>(s.nodes.size()));
  }
  return s;
}

MatX3d smooth_deformation(const MatX3d& X, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const double a = u(rng), b = u(rng), c = u(rng);
  MatX3d x = X;
  for (int i = 0; i < X.rows(); ++i) {
    const Eigen::Vector3d p = X.row(i).transpose();
    x.row(i) +=
        amplitude * Eigen::Vector3d(std::sin(2 * p.y() + a), std::cos(3 * p.z() + b) * p.x(),
                                    std::sin(p.x() * p.y() + c))
                        .transpose();
    x(i, 0) *= 1.0 + 0.3 * amplitude;
  }
  return x;
}

bool chain_covers(const SphereTree& t, int node, const Eigen::Vector3d& p) {
  const Sphere& s = t.spheres[node];
  if ((p - s.center()).norm() > s.r * (1 + 1e-12)) return false;
  if (t.is_leaf(node)) return true;
  for (int c = 0; c < t.child_count[node]; ++c)
    if (chain_covers(t, t.first_child[node] + c, p)) return true;
  return false;
}

TEST(SphereUpdate, TranslationMovesSpheresRigidly) {
  const SurfaceMesh m = make_torus(1.0, 0.3, 16, 8);
  SphereTree t = build_octree_tree(m.V, m.F, {});
  const SurfaceMesh coarse = make_icosphere(1, 1.2);
  associate_nearest_nodes(t, coarse.V, {});
  MatX3d x = coarse.V;
  x.rowwise() += Eigen::RowVector3d(0.3, -2.0, 5.0);
  for (auto mode : {SphereUpdateMode::PaperRatio, SphereUpdateMode::DisplacementBound}) {
    SphereUpdateOptions o;
    o.mode = mode;
    update_spheres(t, coarse.V, x, o);
    for (int i = 0; i < t.num_nodes(); ++i) {
      EXPECT_NEAR(t.spheres[i].x, t.rest_spheres[i].x + 0.3, 1e-12);
      EXPECT_NEAR(t.spheres[i].y, t.rest_spheres[i].y - 2.0, 1e-12);
      EXPECT_NEAR(t.spheres[i].z, t.rest_spheres[i].z + 5.0, 1e-12);
      EXPECT_NEAR(t.spheres[i].r, t.rest_spheres[i].r, 1e-12);
    }
  }
}

TEST(SphereUpdate, PaperRatioScalesByLargestDistanceRatio) {
  // One sphere, two nodes: centre moves by the mean displacement; the radius
  // scales by max |x_j - c| / |X_j - C|.
  SphereTree t;
  t.spheres = {{0, 0, 0, 2}};
  build_topology(t, {-1});
  MatX3d X(2, 3), x(2, 3);
  X << 1, 0, 0, -1, 0, 0;
  x << 3, 0, 0, -1, 0, 0;  // mean displacement (1,0,0); distances 2 and 2 from (1,0,0)
  associate_nearest_nodes(t, X, {});
  update_spheres(t, X, x, {});
  EXPECT_DOUBLE_EQ(t.spheres[0].x, 1.0);
  EXPECT_DOUBLE_EQ(t.spheres[0].r, 4.0);
  SphereUpdateOptions o;
  o.mode = SphereUpdateMode::DisplacementBound;
  o.margin = 0.25;
  update_spheres(t, X, x, o);
  EXPECT_DOUBLE_EQ(t.spheres[0].r, 2.0 + 1.0 + 0.25);  // deviations |(2,0,0)-(1,0,0)| = 1
}

TEST(SphereUpdate, DisplacementBoundKeepsCoveringUnderConvexSteering) {
  const Steered s = make_steered(make_icosphere(3), make_icosphere(1, 1.05));
  SphereTree t = build_octree_tree(s.dense.V, s.dense.F, {});
  associate_steering_nodes(t, s.coarse, s.dense.V, s.dense.F, s.off, s.nodes);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 4; ++trial) {
    const MatX3d x = smooth_deformation(s.coarse, 0.1 + 0.1 * trial, 11 + trial);
    const MatX3d V = s.deform(x);
    SphereUpdateOptions o;
    o.mode = SphereUpdateMode::DisplacementBound;
    update_spheres(t, s.coarse, x, o);
    for (int l = 0; l < t.num_levels(); ++l)
      EXPECT_EQ(measure_coverage(t, V, l).num_uncovered, 0) << "level " << l;
    // Interior points of deformed triangles: a chain covers each.
    for (int f = 0; f < s.dense.F.rows(); f += 3) {
      double a = u(rng), b = u(rng);
      if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
      }
      const Eigen::Vector3d p = (1 - a - b) * V.row(s.dense.F(f, 0)).transpose() +
                                a * V.row(s.dense.F(f, 1)).transpose() +
                                b * V.row(s.dense.F(f, 2)).transpose();
      ASSERT_TRUE(chain_covers(t, 0, p)) << "face " << f;
    }
    // The paper's heuristic is measured, not guaranteed; it must stay finite.
    update_spheres(t, s.coarse, x, {});
    const CoverageReport rep = measure_coverage(t, V);
    EXPECT_GE(rep.uncovered_fraction, 0.0);
    EXPECT_LE(rep.uncovered_fraction, 1.0);
  }
}

TEST(SphereUpdate, ErrorsAreReported) {
  const SurfaceMesh m = make_icosphere(1);
  SphereTree t = build_octree_tree(m.V, m.F, {});
  EXPECT_THROW(update_spheres(t, m.V, m.V, {}), ParameterError);  // no association
  associate_nearest_nodes(t, m.V, {});
  EXPECT_THROW(update_spheres(t, m.V, m.V.topRows(3), {}), ParameterError);
  MatX3d x = m.V;
  x(t.assoc_nodes[0], 1) = std::nan("");
  EXPECT_THROW(update_spheres(t, m.V, x, {}), NumericalError);
}

TEST(Coverage, MatchesBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1), ur(0.01, 0.3);
  SphereTree t;
  std::vector<int32_t> parent{-1};
  t.spheres.push_back({0, 0, 0, 0.5});
  for (int i = 0; i < 8; ++i) {
    t.spheres.push_back({u(rng), u(rng), u(rng), 0.4});
    parent.push_back(0);
  }
  for (int i = 0; i < 200; ++i) {
    t.spheres.push_back({u(rng), u(rng), u(rng), i == 0 ? 3.0 : ur(rng)});
    parent.push_back(1 + i / 25);
  }
  build_topology(t, parent);
  MatX3d P(2000, 3);
  for (int i = 0; i < P.rows(); ++i) P.row(i) << 2 * u(rng), 2 * u(rng), 2 * u(rng);
  for (int level : {-1, 0, 1, 2}) {
    const CoverageReport rep = measure_coverage(t, P, level);
    int expected = 0;
    double gap = 0;
    for (int v = 0; v < P.rows(); ++v) {
      double best = INFINITY;
      for (int i = 0; i < t.num_nodes(); ++i) {
        const bool in_cut = level < 0
                                ? t.is_leaf(i)
                                : (t.level[i] == level || (t.level[i] < level && t.is_leaf(i)));
        if (in_cut)
          best = std::min(best,
                          (P.row(v).transpose() - t.spheres[i].center()).norm() - t.spheres[i].r);
      }
      if (best > 0) {
        ++expected;
        gap = std::max(gap, best);
      }
    }
    EXPECT_EQ(rep.num_uncovered, expected) << "level " << level;
    EXPECT_NEAR(rep.max_gap, gap, 1e-12);
  }
  EXPECT_THROW(measure_coverage(t, P, 3), ParameterError);
}

}  // namespace
}  // namespace icd::collision

namespace icd::collision {
namespace {

// enclose_children turns a wrapped tree into a layered one: every parent
// then contains each child sphere (checked on sample points of the child's
// boundary, an independent test of containment), only radii grow, centres
// and leaves stay.
TEST(SphereUpdate, EncloseChildrenMakesEveryParentContainItsChildren) {
  const SurfaceMesh m = make_icosphere(3, 1.0);
  OctreeTreeOptions o;
  o.levels = 4;
  SphereTree t = build_octree_tree(m.V, m.F, o);
  std::mt19937 rng(0);
  std::normal_distribution<double> g;
  for (Sphere& s : t.spheres) s.r *= 0.6;  // wrapped: children poke out of their parents
  const SphereTree before = t;
  enclose_children(t);
  int grown = 0;
  for (int i = 0; i < t.num_nodes(); ++i) {
    EXPECT_EQ(t.spheres[i].center(), before.spheres[i].center());
    EXPECT_GE(t.spheres[i].r, before.spheres[i].r);
    if (t.child_count[i] == 0) {
      EXPECT_EQ(t.spheres[i].r, before.spheres[i].r);
    }
    grown += t.spheres[i].r > before.spheres[i].r;
    for (int c = t.first_child[i]; c < t.first_child[i] + t.child_count[i]; ++c)
      for (int k = 0; k < 64; ++k) {
        const Eigen::Vector3d d = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
        const Eigen::Vector3d p = t.spheres[c].center() + t.spheres[c].r * d;
        EXPECT_LE((p - t.spheres[i].center()).norm(), t.spheres[i].r * (1 + 1e-12));
      }
  }
  EXPECT_GT(grown, 0);
}

}  // namespace
}  // namespace icd::collision
