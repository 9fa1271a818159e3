#include <gtest/gtest.h>

#include <array>
#include <random>

#include <Eigen/Geometry>

#include <icd/collision/aabb_tree.hpp>
#include <icd/collision/exact_predicates.hpp>
#include <icd/collision/triangle_intersection.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::collision {
namespace {

using Vec = Eigen::Vector3d;
using IVec = std::array<long long, 3>;

IVec sub(const IVec& a, const IVec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
IVec cross(const IVec& a, const IVec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
long long dot(const IVec& a, const IVec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
bool zero(const IVec& a) { return a[0] == 0 && a[1] == 0 && a[2] == 0; }

// Independent oracle: separating-axis test in exact integer arithmetic for
// non-degenerate triangles (axes: both normals, the 9 edge-edge crosses and
// the 6 in-plane edge normals, which settle the coplanar case).
bool sat_intersect(const std::array<IVec, 3>& A, const std::array<IVec, 3>& B) {
  std::vector<IVec> axes;
  const IVec na = cross(sub(A[1], A[0]), sub(A[2], A[0])),
             nb = cross(sub(B[1], B[0]), sub(B[2], B[0]));
  axes.push_back(na);
  axes.push_back(nb);
  for (int i = 0; i < 3; ++i) {
    const IVec ea = sub(A[(i + 1) % 3], A[i]), eb = sub(B[(i + 1) % 3], B[i]);
    for (int j = 0; j < 3; ++j) axes.push_back(cross(ea, sub(B[(j + 1) % 3], B[j])));
    axes.push_back(cross(na, ea));
    axes.push_back(cross(nb, eb));
  }
  for (const IVec& ax : axes) {
    if (zero(ax)) continue;
    long long amin = LLONG_MAX, amax = LLONG_MIN, bmin = LLONG_MAX, bmax = LLONG_MIN;
    for (int k = 0; k < 3; ++k) {
      amin = std::min(amin, dot(ax, A[k]));
      amax = std::max(amax, dot(ax, A[k]));
      bmin = std::min(bmin, dot(ax, B[k]));
      bmax = std::max(bmax, dot(ax, B[k]));
    }
    if (amax < bmin || bmax < amin) return false;
  }
  return true;
}

Vec to_vec(const IVec& a) { return Vec(double(a[0]), double(a[1]), double(a[2])); }

TEST(ExactPredicates, Orient3dAgreesWithIntegerDeterminantAndIsExactNearZero) {
  std::mt19937 rng(0);
  std::uniform_int_distribution<int> c(-200000, 200000);
  for (int t = 0; t < 20000; ++t) {
    std::array<IVec, 4> p;
    for (auto& q : p) q = {c(rng), c(rng), c(rng)};
    if (t % 3 == 0)
      p[3] = {p[0][0] + p[1][0] - p[2][0], p[0][1] + p[1][1] - p[2][1],
              p[0][2] + p[1][2] - p[2][2]};  // coplanar
    // Differences < 4e5: the exact determinant fits in 64-bit integers, while
    // the double products round (so near-coplanar cases take the exact path).
    const long long exact = dot(sub(p[1], p[0]), cross(sub(p[2], p[0]), sub(p[3], p[0])));
    const int expected = exact > 0 ? 1 : (exact < 0 ? -1 : 0);
    ASSERT_EQ(orient3d(to_vec(p[0]), to_vec(p[1]), to_vec(p[2]), to_vec(p[3])), expected);
  }
  // Points that are nearly coplanar in floating point: a plane through three
  // points with non-representable coordinates, the fourth perturbed by one ulp.
  const Vec a(0.1, 0.2, 0.3), b(1.7, -0.3, 0.9), c2(-0.4, 1.1, 0.25);
  for (int k = 0; k < 100; ++k) {
    const double s = 0.37 + 0.01 * k;
    Vec d = a + s * (b - a) + (1 - s) * (c2 - a);  // coplanar up to rounding
    const int o = orient3d(a, b, c2, d);
    // Moving d along the normal by a tiny amount must give consistent signs.
    const Vec n = (b - a).cross(c2 - a).normalized();
    EXPECT_EQ(orient3d(a, b, c2, d + 1e-9 * n), 1);
    EXPECT_EQ(orient3d(a, b, c2, d - 1e-9 * n), -1);
    // Antisymmetry under swapping two points is exact.
    EXPECT_EQ(orient3d(b, a, c2, d), -o);
    EXPECT_EQ(orient3d(a, c2, b, d), -o);
  }
  EXPECT_EQ(orient2d(0, 0, 1, 1, 3, 3), 0);
  EXPECT_EQ(orient2d(0.1, 0.1, 0.2, 0.2, 0.3, 0.3 + 1e-17),
            orient2d(0.3, 0.3 + 1e-17, 0.1, 0.1, 0.2, 0.2));
}

TEST(TriangleIntersection, SmallIntegerGridAgainstSeparatingAxisOracle) {
  // Coordinates in {-2..2}: touching, shared vertices, coplanar overlaps abound.
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> c(-2, 2);
  int tested = 0, hits = 0, coplanar = 0;
  while (tested < 30000) {
    std::array<IVec, 3> A, B;
    for (auto& q : A) q = {c(rng), c(rng), c(rng)};
    for (auto& q : B) q = {c(rng), c(rng), c(rng)};
    if (tested % 4 == 0)  // force a coplanar configuration
      for (auto* T : {&A, &B})
        for (auto& q : *T) q[2] = 1;
    if (zero(cross(sub(A[1], A[0]), sub(A[2], A[0]))) ||
        zero(cross(sub(B[1], B[0]), sub(B[2], B[0]))))
      continue;
    ++tested;
    const bool expected = sat_intersect(A, B);
    hits += expected;
    const IVec na = cross(sub(A[1], A[0]), sub(A[2], A[0]));
    if (dot(na, sub(B[0], A[0])) == 0 && dot(na, sub(B[1], A[0])) == 0 &&
        dot(na, sub(B[2], A[0])) == 0)
      ++coplanar;
    const bool got = triangles_intersect(to_vec(A[0]), to_vec(A[1]), to_vec(A[2]), to_vec(B[0]),
                                         to_vec(B[1]), to_vec(B[2]));
    ASSERT_EQ(got, expected) << "case " << tested;
    // Symmetric in the triangles and in vertex order.
    ASSERT_EQ(triangles_intersect(to_vec(B[2]), to_vec(B[0]), to_vec(B[1]), to_vec(A[1]),
                                  to_vec(A[0]), to_vec(A[2])),
              expected);
  }
  EXPECT_GT(hits, 3000);
  EXPECT_LT(hits, 27000);
  EXPECT_GT(coplanar, 100);
}

TEST(TriangleIntersection, RandomFloatTrianglesAndIntersectionPoints) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  int hits = 0;
  for (int t = 0; t < 20000; ++t) {
    std::array<Vec, 3> A, B;
    for (auto& q : A) q = Vec(u(rng), u(rng), u(rng));
    for (auto& q : B) q = Vec(u(rng), u(rng), u(rng)) * 0.8;
    // Oracle: SAT in floating point (generic inputs: no ties).
    std::vector<Vec> axes;
    const Vec na = (A[1] - A[0]).cross(A[2] - A[0]), nb = (B[1] - B[0]).cross(B[2] - B[0]);
    axes = {na, nb};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        axes.push_back((A[(i + 1) % 3] - A[i]).cross(B[(j + 1) % 3] - B[j]));
    bool separated = false;
    for (const Vec& ax : axes) {
      double amin = INFINITY, amax = -INFINITY, bmin = INFINITY, bmax = -INFINITY;
      for (int k = 0; k < 3; ++k) {
        amin = std::min(amin, ax.dot(A[k]));
        amax = std::max(amax, ax.dot(A[k]));
        bmin = std::min(bmin, ax.dot(B[k]));
        bmax = std::max(bmax, ax.dot(B[k]));
      }
      separated = separated || amax < bmin || bmax < amin;
    }
    const bool got = triangles_intersect(A[0], A[1], A[2], B[0], B[1], B[2]);
    ASSERT_EQ(got, !separated) << "case " << t;
    hits += got;
    const auto pts = triangle_intersection_points(A[0], A[1], A[2], B[0], B[1], B[2]);
    EXPECT_EQ(pts.empty(), !got);
    for (const Vec& p : pts) {
      // On both planes and inside both triangles (barycentric within rounding).
      for (const auto* T : {&A, &B}) {
        const Vec n = ((*T)[1] - (*T)[0]).cross((*T)[2] - (*T)[0]);
        ASSERT_NEAR(n.normalized().dot(p - (*T)[0]), 0.0, 1e-9);
        for (int k = 0; k < 3; ++k) {
          const Vec e = (*T)[(k + 1) % 3] - (*T)[k];
          ASSERT_GE(n.cross(e).normalized().dot(p - (*T)[k]), -1e-9);  // inward edge normal
        }
      }
    }
  }
  EXPECT_GT(hits, 500);
}

TEST(TriangleIntersection, DegenerateAndNearDegenerateCases) {
  const Vec o(0, 0, 0), x(1, 0, 0), y(0, 1, 0);
  // Touching a vertex on the face, then lifted by +-1e-12.
  for (double h : {0.0, -1e-12, 1e-12, -1e-300, 1e-300}) {
    const bool got =
        triangles_intersect(o, x, y, Vec(0.2, 0.2, h), Vec(0.3, 0.2, 1), Vec(0.2, 0.3, 1));
    EXPECT_EQ(got, h <= 0.0) << h;
  }
  // Shared vertex only, shared edge, coplanar containment, coplanar disjoint.
  EXPECT_TRUE(triangles_intersect(o, x, y, o, Vec(-1, 0, 0), Vec(0, 0, 1)));
  EXPECT_TRUE(triangles_intersect(o, x, y, o, x, Vec(0, -1, 0)));
  EXPECT_TRUE(triangles_intersect(o, x, y, Vec(0.1, 0.1, 0), Vec(0.2, 0.1, 0), Vec(0.1, 0.2, 0)));
  EXPECT_FALSE(triangles_intersect(o, x, y, Vec(0.6, 0.6, 0), Vec(2, 0.6, 0), Vec(0.6, 2, 0)));
  EXPECT_TRUE(triangles_intersect(o, x, y, Vec(0.5, 0.5, 0), Vec(2, 0.5, 0),
                                  Vec(0.5, 2, 0)));  // touch at (0.5,0.5)
  // Edge crossing an edge in 3D (non-coplanar) and just missing it.
  EXPECT_TRUE(triangles_intersect(o, x, y, Vec(0.5, -1, 0), Vec(0.5, 1, 0), Vec(0.5, 0, 1)));
  EXPECT_FALSE(
      triangles_intersect(o, x, y, Vec(0.5, -1, 1e-12), Vec(0.5, 1, 1e-12), Vec(0.5, 0, 1)));
  // Zero-area triangles: a segment through the face, a segment beside it, a point on it.
  EXPECT_TRUE(
      triangles_intersect(o, x, y, Vec(0.2, 0.2, -1), Vec(0.2, 0.2, 1), Vec(0.2, 0.2, 0.5)));
  EXPECT_FALSE(triangles_intersect(o, x, y, Vec(2, 2, -1), Vec(2, 2, 1), Vec(2, 2, 0.5)));
  EXPECT_TRUE(triangles_intersect(o, x, y, Vec(0.3, 0.3, 0), Vec(0.3, 0.3, 0), Vec(0.3, 0.3, 0)));
  EXPECT_FALSE(triangles_intersect(o, x, y, Vec(0.3, 0.3, 1e-12), Vec(0.3, 0.3, 1e-12),
                                   Vec(0.3, 0.3, 1e-12)));
  // Two collinear segments (both triangles degenerate), overlapping or not.
  EXPECT_TRUE(triangles_intersect(o, x, 0.5 * x, 0.7 * x, 2 * x, 1.5 * x));
  EXPECT_FALSE(triangles_intersect(o, x, 0.5 * x, 1.1 * x, 2 * x, 1.5 * x));
  EXPECT_TRUE(triangles_intersect(o, o, o, o, o, o));
}

TEST(AabbTree, IntersectingPairsEqualBruteForceAtRestAndAfterRefit) {
  const SurfaceMesh a = make_icosphere(2);
  SurfaceMesh b = make_torus(0.9, 0.3, 20, 10);
  b.V.rowwise() += Eigen::RowVector3d(0.4, 0.1, 0.05);
  AabbTree ta(a.V, a.F), tb(b.V, b.F, 2);
  const auto got = intersecting_triangle_pairs(ta, a.V, a.F, tb, b.V, b.F);
  const auto expected = intersecting_triangle_pairs_brute_force(a.V, a.F, b.V, b.F);
  EXPECT_GT(expected.size(), 20u);
  EXPECT_EQ(got, expected);
  MatX3d Vb = b.V;
  for (int i = 0; i < Vb.rows(); ++i)
    Vb.row(i) += 0.2 * Eigen::RowVector3d(std::sin(3 * Vb(i, 1)), 0.5 * Vb(i, 0), 0.1);
  tb.refit(Vb, b.F);
  const auto got2 = intersecting_triangle_pairs(ta, a.V, a.F, tb, Vb, b.F);
  const auto expected2 = intersecting_triangle_pairs_brute_force(a.V, a.F, Vb, b.F);
  EXPECT_NE(expected2, expected);
  EXPECT_EQ(got2, expected2);
}

}  // namespace
}  // namespace icd::collision
