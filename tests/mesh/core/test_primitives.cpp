#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <map>
#include <random>
#include <utility>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd {
namespace {

// Total signed volume enclosed by a closed, outward-oriented surface
// (divergence theorem), independent of any tet decomposition.
double enclosed_volume(const MatX3d& V, const MatX3i& F) {
  double vol = 0.0;
  for (int f = 0; f < F.rows(); ++f)
    vol += V.row(F(f, 0)).dot(V.row(F(f, 1)).cross(V.row(F(f, 2)))) / 6.0;
  return vol;
}

// Every directed edge appears once and its reverse once: closed, consistently oriented.
bool closed_and_oriented(const MatX3i& F) {
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++directed[{F(f, k), F(f, (k + 1) % 3)}];
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;
    auto it = directed.find({e.second, e.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  return true;
}

TEST(Primitives, BoxTetMeshVolumesAndBoundary) {
  BoxMeshOptions o;
  o.size = {1.0, 0.1, 0.2};
  o.nx = 7;
  o.ny = 2;
  o.nz = 3;
  const TetMesh m = make_box_tet_mesh(o);
  EXPECT_EQ(m.V.rows(), 8 * 3 * 4);
  EXPECT_EQ(m.T.rows(), 6 * 7 * 2 * 3);
  const Eigen::VectorXd vol = signed_tet_volumes(m.V, m.T);
  EXPECT_GT(vol.minCoeff(), 0.0);
  EXPECT_NEAR(vol.sum(), 0.02, 1e-14);
  // Boundary: 2 triangles per boundary quad.
  EXPECT_EQ(m.F.rows(), 2 * 2 * (7 * 2 + 7 * 3 + 2 * 3));
  EXPECT_TRUE(closed_and_oriented(m.F));
  EXPECT_NEAR(enclosed_volume(m.V, m.F), 0.02, 1e-14);
}

TEST(Primitives, IcosphereIsClosedAndConvergesToSphereVolume) {
  double prev_err = 1e9;
  for (int s = 0; s <= 4; ++s) {
    const SurfaceMesh m = make_icosphere(s, 2.0);
    EXPECT_EQ(m.F.rows(), 20 << (2 * s));
    EXPECT_TRUE(closed_and_oriented(m.F));
    const double err = std::abs(enclosed_volume(m.V, m.F) - 4.0 / 3.0 * M_PI * 8.0);
    EXPECT_LT(err, prev_err);
    prev_err = err;
  }
  EXPECT_LT(prev_err / (4.0 / 3.0 * M_PI * 8.0), 0.01);
}

TEST(Primitives, BoxSurfaceAndTorus) {
  const SurfaceMesh box = make_box_surface({0, 0, 0}, {1, 2, 3});
  EXPECT_TRUE(closed_and_oriented(box.F));
  EXPECT_NEAR(enclosed_volume(box.V, box.F), 6.0, 1e-14);
  const SurfaceMesh torus = make_torus(2.0, 0.5, 64, 32);
  EXPECT_TRUE(closed_and_oriented(torus.F));
  const double exact = 2 * M_PI * M_PI * 2.0 * 0.25;
  EXPECT_NEAR(enclosed_volume(torus.V, torus.F), exact, 0.01 * exact);
}

// Brute force: a face of tet e is on the boundary iff no other tet has all
// three of its vertices; faces listed by (tet, local face) as documented.
TEST(Primitives, BoundaryFacesMatchBruteForceOnPerforatedBox) {
  BoxMeshOptions o;
  o.nx = 4;
  o.ny = 3;
  o.nz = 2;
  const TetMesh full = make_box_tet_mesh(o);
  std::mt19937 rng(0);
  std::vector<int> kept;
  for (int e = 0; e < full.T.rows(); ++e)
    if (rng() % 3 != 0) kept.push_back(e);
  MatX4i T(static_cast<Eigen::Index>(kept.size()), 4);
  for (size_t i = 0; i < kept.size(); ++i) T.row(i) = full.T.row(kept[i]);
  static constexpr int local[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::vector<Eigen::RowVector3i> expected;
  for (int e = 0; e < T.rows(); ++e)
    for (const auto& f : local) {
      bool shared = false;
      for (int g = 0; g < T.rows() && !shared; ++g) {
        if (g == e) continue;
        int hits = 0;
        for (int k = 0; k < 3; ++k) hits += (T.row(g).array() == T(e, f[k])).any() ? 1 : 0;
        shared = hits == 3;
      }
      if (!shared) expected.emplace_back(T(e, f[0]), T(e, f[1]), T(e, f[2]));
    }
  const MatX3i F = boundary_faces(T);
  ASSERT_EQ(F.rows(), static_cast<Eigen::Index>(expected.size()));
  for (Eigen::Index i = 0; i < F.rows(); ++i) EXPECT_EQ(F.row(i), expected[i]) << i;
}

TEST(Primitives, BadParametersThrow) {
  BoxMeshOptions o;
  o.nx = 0;
  EXPECT_THROW(make_box_tet_mesh(o), ParameterError);
  o.nx = 1;
  o.size = {1, -1, 1};
  EXPECT_THROW(make_box_tet_mesh(o), ParameterError);
  EXPECT_THROW(make_torus(1.0, 2.0, 8, 8), ParameterError);
  EXPECT_THROW(make_icosphere(-1), ParameterError);
}

}  // namespace
}  // namespace icd

namespace icd {
namespace {

// boundary_nodes: the distinct vertices of F, sorted, checked against a
// brute-force membership scan on the box boundary (every vertex of a 2x2x2
// grid but the centre).
TEST(Primitives, BoundaryNodesAreTheDistinctSortedFaceVertices) {
  BoxMeshOptions o;
  o.size = {1, 1, 1};
  o.nx = o.ny = o.nz = 2;
  const TetMesh m = make_box_tet_mesh(o);
  const Eigen::VectorXi b = boundary_nodes(m.F);
  std::vector<int> expected;
  for (int v = 0; v < m.V.rows(); ++v)
    if ((m.F.array() == v).any()) expected.push_back(v);
  ASSERT_EQ(b.size(), static_cast<Eigen::Index>(expected.size()));
  EXPECT_EQ(b.size(), 26);
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(b[i], expected[i]);
}

}  // namespace
}  // namespace icd
