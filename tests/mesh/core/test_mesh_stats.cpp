// compute_surface_stats against analytic values of the primitives and a
// brute-force edge count on random triangle soups.
#include <gtest/gtest.h>

#include <map>
#include <numbers>
#include <random>
#include <utility>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/mesh_stats.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd {
namespace {

SurfaceMesh drop_face(const SurfaceMesh& m, int f) {
  SurfaceMesh out = m;
  out.F.resize(m.F.rows() - 1, 3);
  for (int i = 0, k = 0; i < m.F.rows(); ++i)
    if (i != f) out.F.row(k++) = m.F.row(i);
  return out;
}

SurfaceMesh append(const SurfaceMesh& a, const SurfaceMesh& b) {
  SurfaceMesh out;
  out.V.resize(a.V.rows() + b.V.rows(), 3);
  out.V << a.V, b.V;
  out.F.resize(a.F.rows() + b.F.rows(), 3);
  out.F << a.F, (b.F.array() + static_cast<int>(a.V.rows())).matrix();
  return out;
}

TEST(MeshStats, BoxIsExact) {
  const SurfaceStats s = compute_surface_stats(make_box_surface({0, 0, 0}, {1, 2, 3}));
  EXPECT_EQ(s.vertices, 8);
  EXPECT_EQ(s.faces, 12);
  EXPECT_EQ(s.edges, 18);
  EXPECT_DOUBLE_EQ(s.area, 2.0 * (1 * 2 + 2 * 3 + 1 * 3));
  EXPECT_DOUBLE_EQ(s.volume, 6.0);
  EXPECT_EQ(s.bbox_min, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(s.bbox_max, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.boundary_edges, 0);
  EXPECT_EQ(s.nonmanifold_edges, 0);
  EXPECT_EQ(s.inconsistent_edges, 0);
  EXPECT_EQ(s.duplicate_vertices, 0);
  EXPECT_EQ(s.degenerate_faces, 0);
  EXPECT_EQ(s.components, 1);
  EXPECT_EQ(s.euler_characteristic, 2);
}

TEST(MeshStats, IcosphereAndTorusTopology) {
  for (int sub = 0; sub <= 3; ++sub) {
    const double r = 1.7;
    const SurfaceStats s = compute_surface_stats(make_icosphere(sub, r));
    EXPECT_EQ(s.euler_characteristic, 2);
    EXPECT_EQ(s.boundary_edges, 0);
    EXPECT_EQ(s.nonmanifold_edges, 0);
    EXPECT_EQ(s.inconsistent_edges, 0);
    EXPECT_EQ(s.edges, 3 * s.faces / 2);
    // Inscribed polyhedron: strictly below the sphere's area and volume.
    EXPECT_LT(s.area, 4 * std::numbers::pi * r * r);
    EXPECT_LT(s.volume, 4.0 / 3.0 * std::numbers::pi * r * r * r);
    EXPECT_GT(s.volume, 0.6 * 4.0 / 3.0 * std::numbers::pi * r * r * r);
  }
  const SurfaceStats t = compute_surface_stats(make_torus(2.0, 0.5, 16, 9));
  EXPECT_EQ(t.euler_characteristic, 0);
  EXPECT_EQ(t.boundary_edges, 0);
  EXPECT_EQ(t.components, 1);
}

TEST(MeshStats, OpenBoxTwoBoxesFlippedFace) {
  const SurfaceMesh box = make_box_surface({0, 0, 0}, {1, 1, 1});
  const SurfaceStats open = compute_surface_stats(drop_face(box, 4));
  EXPECT_EQ(open.boundary_edges, 3);
  EXPECT_EQ(open.euler_characteristic, 1);  // a disc

  const SurfaceMesh two = append(box, make_box_surface({3, 0, 0}, {4, 1, 1}));
  const SurfaceStats s2 = compute_surface_stats(two);
  EXPECT_EQ(s2.components, 2);
  EXPECT_EQ(s2.euler_characteristic, 4);
  EXPECT_DOUBLE_EQ(s2.volume, 2.0);

  SurfaceMesh flipped = box;
  std::swap(flipped.F(0, 1), flipped.F(0, 2));
  const SurfaceStats sf = compute_surface_stats(flipped);
  EXPECT_EQ(sf.inconsistent_edges, 3);
  EXPECT_EQ(sf.boundary_edges, 0);
}

TEST(MeshStats, DuplicatesDegenerateAndNonManifold) {
  SurfaceMesh m = make_box_surface({0, 0, 0}, {1, 1, 1});
  // A copy of vertex 7 (unreferenced) and the midpoint of edge 0-1.
  m.V.conservativeResize(10, 3);
  m.V.row(8) = m.V.row(7);
  m.V.row(9) = 0.5 * (m.V.row(0) + m.V.row(1));
  // Faces: one with a repeated index, one collinear (0, 9, 1), and two fins
  // on edge 0-1 making it non-manifold (4 faces).
  m.F.conservativeResize(16, 3);
  m.F.row(12) << 2, 2, 3;
  m.F.row(13) << 0, 9, 1;
  m.F.row(14) << 0, 1, 6;
  m.F.row(15) << 1, 0, 5;
  const SurfaceStats s = compute_surface_stats(m);
  EXPECT_EQ(s.duplicate_vertices, 1);
  EXPECT_EQ(s.unreferenced_vertices, 1);
  EXPECT_EQ(s.degenerate_faces, 2);
  EXPECT_GE(s.nonmanifold_edges, 1);
}

// Brute force: count faces per undirected edge with a std::map.
TEST(MeshStats, EdgeCountsMatchBruteForceOnRandomSoups) {
  std::mt19937 rng(0);
  for (int trial = 0; trial < 20; ++trial) {
    const int nv = 5 + static_cast<int>(rng() % 20), nf = 1 + static_cast<int>(rng() % 60);
    SurfaceMesh m;
    m.V = MatX3d::Random(nv, 3);
    m.F.resize(nf, 3);
    for (int f = 0; f < nf; ++f) {
      int a = static_cast<int>(rng() % nv), b, c;
      do b = static_cast<int>(rng() % nv);
      while (b == a);
      do c = static_cast<int>(rng() % nv);
      while (c == a || c == b);
      m.F.row(f) << a, b, c;
    }
    std::map<std::pair<int, int>, std::pair<int, int>> edges;  // -> (count, forward)
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        const int i = m.F(f, k), j = m.F(f, (k + 1) % 3);
        auto& e = edges[{std::min(i, j), std::max(i, j)}];
        ++e.first;
        e.second += i < j;
      }
    int64_t boundary = 0, nonmanifold = 0, inconsistent = 0;
    for (const auto& [key, e] : edges) {
      boundary += e.first == 1;
      nonmanifold += e.first > 2;
      inconsistent += e.first == 2 && e.second != 1;
    }
    const SurfaceStats s = compute_surface_stats(m);
    EXPECT_EQ(s.edges, static_cast<int64_t>(edges.size()));
    EXPECT_EQ(s.boundary_edges, boundary);
    EXPECT_EQ(s.nonmanifold_edges, nonmanifold);
    EXPECT_EQ(s.inconsistent_edges, inconsistent);
    EXPECT_EQ(s.euler_characteristic, nv - static_cast<int64_t>(edges.size()) + nf);
  }
}

TEST(MeshStats, BadInputThrows) {
  SurfaceMesh m = make_box_surface({0, 0, 0}, {1, 1, 1});
  m.F(3, 1) = 8;
  EXPECT_THROW(compute_surface_stats(m), ParameterError);
  m.F(3, 1) = 2;
  m.V(2, 2) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(compute_surface_stats(m), ParameterError);
  const SurfaceStats empty = compute_surface_stats(SurfaceMesh{});
  EXPECT_EQ(empty.vertices, 0);
  EXPECT_EQ(empty.euler_characteristic, 0);
}

}  // namespace
}  // namespace icd
