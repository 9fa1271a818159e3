// Vertex- and face-order independence of the preprocessing (issue 30): the
// same triangles listed in another order give the same coarse mesh and the
// same sphere tree.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/pipeline/canonical.hpp>
#include <icd/mesh/pipeline/preprocess.hpp>

namespace icd::mesh {
namespace {

// `m` with shuffled vertices and faces, each face rotated by a random step
// (orientation kept): the same oriented triangles.
SurfaceMesh permuted(const SurfaceMesh& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<int> perm(static_cast<std::size_t>(m.V.rows()));
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);  // old -> new
  std::vector<int> forder(static_cast<std::size_t>(m.F.rows()));
  std::iota(forder.begin(), forder.end(), 0);
  std::shuffle(forder.begin(), forder.end(), rng);
  SurfaceMesh out;
  out.V.resize(m.V.rows(), 3);
  for (int i = 0; i < m.V.rows(); ++i) out.V.row(perm[static_cast<std::size_t>(i)]) = m.V.row(i);
  out.F.resize(m.F.rows(), 3);
  std::uniform_int_distribution<int> step(0, 2);
  for (int f = 0; f < m.F.rows(); ++f) {
    const int src = forder[static_cast<std::size_t>(f)], s = step(rng);
    for (int k = 0; k < 3; ++k) out.F(f, k) = perm[static_cast<std::size_t>(m.F(src, (k + s) % 3))];
  }
  return out;
}

// The oriented triangles as coordinate triples, each rotated to start at its
// lexicographically smallest corner: equal sets = the same surface.
std::set<std::array<double, 9>> triangles(const SurfaceMesh& m) {
  std::set<std::array<double, 9>> out;
  for (int f = 0; f < m.F.rows(); ++f) {
    std::array<std::array<double, 3>, 3> c;
    for (int k = 0; k < 3; ++k) c[k] = {m.V(m.F(f, k), 0), m.V(m.F(f, k), 1), m.V(m.F(f, k), 2)};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.insert({c[0][0], c[0][1], c[0][2], c[1][0], c[1][1], c[1][2], c[2][0], c[2][1], c[2][2]});
  }
  return out;
}

SurfaceMesh test_shape() {
  // A torus bent in z (no mirror symmetry in z), 576 faces.
  SurfaceMesh m = make_torus(1.0, 0.35, 24, 12);
  for (int i = 0; i < m.V.rows(); ++i) m.V(i, 2) += 0.05 * m.V(i, 0) * m.V(i, 0);
  return m;
}

TEST(CanonicalOrder, IsAFunctionOfTheOrientedTriangles) {
  const SurfaceMesh m = test_shape();
  const SurfaceMesh p = permuted(m, 3);
  ASSERT_FALSE(p.V == m.V);  // the permutation did move vertices
  std::vector<int> map;
  const SurfaceMesh a = canonical_order(m), b = canonical_order(p, &map);
  EXPECT_TRUE(a.V == b.V);
  EXPECT_TRUE(a.F == b.F);
  EXPECT_EQ(triangles(a), triangles(m));  // same surface, same orientation
  ASSERT_EQ(map.size(), static_cast<std::size_t>(p.V.rows()));
  for (int i = 0; i < p.V.rows(); ++i) EXPECT_TRUE(b.V.row(map[static_cast<std::size_t>(i)]) == p.V.row(i));
  for (int i = 1; i < a.V.rows(); ++i) EXPECT_LE(a.V(i - 1, 0), a.V(i, 0));  // sorted by x first
}

TEST(Preprocess, PermutedInputGivesTheSameCoarseMeshAndSphereTree) {
  PreprocessOptions o;
  o.tetrahedralize.target_tets = 250;
  o.compute_hausdorff = false;
  o.spheres.depth = 2;  // a small medial-axis tree (seconds)
  o.spheres.branching = 4;
  o.spheres.sampling.cover_spacing = 1.0 / 50;
  o.spheres.sampling.medial_spacing = 1.0 / 15;
  const SurfaceMesh m = test_shape();
  const PreprocessResult a = preprocess(m, o), b = preprocess(permuted(m, 7), o);
  EXPECT_EQ(triangles(a.bundle.dense), triangles(b.bundle.dense));
  EXPECT_TRUE(a.bundle.coarse.V == b.bundle.coarse.V);
  EXPECT_TRUE(a.bundle.coarse.T == b.bundle.coarse.T);
  const auto& ta = a.bundle.spheres.rest_spheres;
  const auto& tb = b.bundle.spheres.rest_spheres;
  ASSERT_EQ(ta.size(), tb.size());
  ASSERT_GT(ta.size(), 5u);
  for (std::size_t i = 0; i < ta.size(); ++i) {
    EXPECT_EQ(ta[i].x, tb[i].x) << i;
    EXPECT_EQ(ta[i].y, tb[i].y) << i;
    EXPECT_EQ(ta[i].z, tb[i].z) << i;
    EXPECT_EQ(ta[i].r, tb[i].r) << i;
  }
  EXPECT_EQ(a.bundle.spheres.assoc_nodes, b.bundle.spheres.assoc_nodes);
}

}  // namespace
}  // namespace icd::mesh
