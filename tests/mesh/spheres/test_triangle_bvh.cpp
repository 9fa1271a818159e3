// TriangleBvh and closest_point_on_triangle against brute force.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include <Eigen/Geometry>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/core/triangle_geometry.hpp>
#include <icd/mesh/spheres/triangle_bvh.hpp>

namespace {

using icd::closest_point_on_triangle;
using icd::mesh::TriangleBvh;

/// Nearest of a dense barycentric lattice on the triangle (brute force).
double lattice_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b, const Eigen::Vector3d& c, int n) {
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const Eigen::Vector3d q = a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n);
      best = std::min(best, (q - p).norm());
    }
  }
  return best;
}

TEST(ClosestPointOnTriangle, MatchesADenseLatticeInEveryRegion) {
  std::mt19937 rng(0);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const int n = 300;  // lattice step 1/300 of the edges: distance error < 0.004
  for (int t = 0; t < 60; ++t) {
    const Eigen::Vector3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)),
        c(u(rng), u(rng), u(rng));
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    const Eigen::Vector3d q = closest_point_on_triangle(p, a, b, c);
    const double lattice = lattice_distance(p, a, b, c, n);
    // q lies on the triangle: its distance is never above the lattice's, and
    // the lattice's is at most one lattice cell above the exact minimum.
    EXPECT_LE((q - p).norm(), lattice + 1e-12);
    EXPECT_GE((q - p).norm(), lattice - 0.02);
    // q is on the triangle's plane and inside it (barycentric coordinates >= 0).
    const Eigen::Vector3d nrm = (b - a).cross(c - a);
    EXPECT_NEAR(nrm.normalized().dot(q - a), 0.0, 1e-9);
  }
}

TEST(ClosestPointOnTriangle, DegenerateTrianglesGiveTheirSegment) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(2, 0, 0);  // collinear
  const Eigen::Vector3d q = closest_point_on_triangle(Eigen::Vector3d(1.5, 1, 0), a, b, c);
  EXPECT_NEAR((q - Eigen::Vector3d(1.5, 0, 0)).norm(), 0.0, 1e-12);
  const Eigen::Vector3d r = closest_point_on_triangle(Eigen::Vector3d(3, 1, 0), a, a, a);
  EXPECT_NEAR((r - a).norm(), 0.0, 1e-12);
}

TEST(TriangleBvh, MatchesBruteForceOnSphereAndTorus) {
  for (const icd::SurfaceMesh& mesh : {icd::make_icosphere(3), icd::make_torus(1.0, 0.3, 24, 12)}) {
    const TriangleBvh bvh(mesh.V, mesh.F);
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    std::normal_distribution<double> g(0.0, 1.0);
    for (int t = 0; t < 400; ++t) {
      // Far points, and points near a vertex (within 1e-6 .. 0.1).
      Eigen::Vector3d p(u(rng), u(rng), u(rng));
      if (t % 2 == 1) {
        const double scale = t % 4 == 1 ? 1e-6 : 0.1;
        p = mesh.V.row(t % mesh.V.rows()).transpose() +
            scale * Eigen::Vector3d(g(rng), g(rng), g(rng));
      }
      double brute = std::numeric_limits<double>::infinity();
      int brute_face = -1;
      for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
        const Eigen::Vector3d q = closest_point_on_triangle(
            p, mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)), mesh.V.row(mesh.F(f, 2)));
        if ((q - p).squaredNorm() < brute) brute = (q - p).squaredNorm(), brute_face = int(f);
      }
      ASSERT_GE(brute_face, 0);
      const TriangleBvh::Hit hit = bvh.closest(p);
      EXPECT_NEAR(hit.squared_distance, brute, 1e-14 * (1 + brute)) << t;
      EXPECT_NEAR((hit.point - p).squaredNorm(), hit.squared_distance, 1e-12);
      ASSERT_GE(hit.face, 0);
      const Eigen::Vector3d on_face = closest_point_on_triangle(p, mesh.V.row(mesh.F(hit.face, 0)),
                                                                mesh.V.row(mesh.F(hit.face, 1)),
                                                                mesh.V.row(mesh.F(hit.face, 2)));
      EXPECT_NEAR((on_face - hit.point).norm(), 0.0, 1e-12);
      EXPECT_NEAR(bvh.distance(p), std::sqrt(brute), 1e-12);
    }
  }
}

TEST(TriangleBvh, RejectsEmptyMeshesAndBadIndices) {
  icd::MatX3d V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  icd::MatX3i F(1, 3);
  F << 0, 1, 3;
  EXPECT_THROW(TriangleBvh(V, F), icd::InputError);
  EXPECT_THROW(TriangleBvh(V, icd::MatX3i(0, 3)), icd::InputError);
}

}  // namespace
