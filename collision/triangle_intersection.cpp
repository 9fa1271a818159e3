#include <icd/collision/triangle_intersection.hpp>

#include <algorithm>
#include <array>
#include <cmath>

#include <icd/collision/exact_predicates.hpp>

namespace icd::collision {
namespace {

using Vec = Eigen::Vector3d;

// 2D orientation after dropping coordinate k.
int orient_k(int k, const Vec& a, const Vec& b, const Vec& c) {
  const int u = (k + 1) % 3, v = (k + 2) % 3;
  return orient2d(a[u], a[v], b[u], b[v], c[u], c[v]);
}

// Axis to drop so that the plane of non-collinear (p, q, r) projects one to
// one, or -1 when p, q, r are collinear.
int projection_axis(const Vec& p, const Vec& q, const Vec& r) {
  const Vec n = (q - p).cross(r - p);
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(),
            [&](int i, int j) { return std::abs(n[i]) > std::abs(n[j]); });
  for (int k : order)
    if (orient_k(k, p, q, r) != 0) return k;
  return -1;
}

// c lies in the bounding box of collinear a, b (in projection k).
bool on_segment_k(int k, const Vec& a, const Vec& b, const Vec& c) {
  const int u = (k + 1) % 3, v = (k + 2) % 3;
  return std::min(a[u], b[u]) <= c[u] && c[u] <= std::max(a[u], b[u]) &&
         std::min(a[v], b[v]) <= c[v] && c[v] <= std::max(a[v], b[v]);
}

// Closed 2D segment-segment test in projection k.
bool segments_meet_k(int k, const Vec& a, const Vec& b, const Vec& c, const Vec& d) {
  const int d1 = orient_k(k, c, d, a), d2 = orient_k(k, c, d, b);
  const int d3 = orient_k(k, a, b, c), d4 = orient_k(k, a, b, d);
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  if (d1 == 0 && on_segment_k(k, c, d, a)) return true;
  if (d2 == 0 && on_segment_k(k, c, d, b)) return true;
  if (d3 == 0 && on_segment_k(k, a, b, c)) return true;
  if (d4 == 0 && on_segment_k(k, a, b, d)) return true;
  return false;
}

// Closed point-in-triangle test in projection k (triangle non-degenerate there).
bool point_in_triangle_k(int k, const Vec& x, const Vec& p, const Vec& q, const Vec& r) {
  const int o1 = orient_k(k, p, q, x), o2 = orient_k(k, q, r, x), o3 = orient_k(k, r, p, x);
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

// Closed segment-segment test in 3D (exact).
bool segments_meet_3d(const Vec& a, const Vec& b, const Vec& c, const Vec& d) {
  if (orient3d(a, b, c, d) != 0) return false;
  for (int k = 0; k < 3; ++k)
    if (orient_k(k, a, b, c) != 0 || orient_k(k, a, b, d) != 0 || orient_k(k, c, d, a) != 0 ||
        orient_k(k, c, d, b) != 0)
      return segments_meet_k(k, a, b, c, d);
  // All four points on one line (or coincident): compare along the axis of
  // largest extent, where the order along the line is the coordinate order.
  int k = 0;
  double best = -1;
  for (int i = 0; i < 3; ++i) {
    const double ext = std::max(std::abs(b[i] - a[i]), std::abs(d[i] - c[i]));
    if (ext > best) {
      best = ext;
      k = i;
    }
  }
  if (best == 0.0) return a == c;
  return std::max(std::min(a[k], b[k]), std::min(c[k], d[k])) <=
         std::min(std::max(a[k], b[k]), std::max(c[k], d[k]));
}

bool coplanar_segment_triangle(const Vec& s0, const Vec& s1, const Vec& p, const Vec& q,
                               const Vec& r) {
  const int k = projection_axis(p, q, r);
  if (k < 0)  // zero-area triangle: the union of its edges
    return segments_meet_3d(s0, s1, p, q) || segments_meet_3d(s0, s1, q, r) ||
           segments_meet_3d(s0, s1, r, p);
  if (point_in_triangle_k(k, s0, p, q, r) || point_in_triangle_k(k, s1, p, q, r)) return true;
  return segments_meet_k(k, s0, s1, p, q) || segments_meet_k(k, s0, s1, q, r) ||
         segments_meet_k(k, s0, s1, r, p);
}

}  // namespace

bool segment_triangle_intersect(const Vec& s0, const Vec& s1, const Vec& p, const Vec& q,
                                const Vec& r) {
  const int o0 = orient3d(p, q, r, s0), o1 = orient3d(p, q, r, s1);
  if (o0 * o1 > 0) return false;
  if (o0 == 0 && o1 == 0) return coplanar_segment_triangle(s0, s1, p, q, r);
  // The segment meets the plane in one point; is it inside the closed triangle?
  const int a = orient3d(s0, s1, p, q), b = orient3d(s0, s1, q, r), c = orient3d(s0, s1, r, p);
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

bool triangles_intersect(const Vec& a0, const Vec& a1, const Vec& a2, const Vec& b0, const Vec& b1,
                         const Vec& b2) {
  // Quick rejection: all of one triangle strictly on one side of the other's plane.
  const int sa0 = orient3d(b0, b1, b2, a0), sa1 = orient3d(b0, b1, b2, a1),
            sa2 = orient3d(b0, b1, b2, a2);
  if ((sa0 > 0 && sa1 > 0 && sa2 > 0) || (sa0 < 0 && sa1 < 0 && sa2 < 0)) return false;
  const int sb0 = orient3d(a0, a1, a2, b0), sb1 = orient3d(a0, a1, a2, b1),
            sb2 = orient3d(a0, a1, a2, b2);
  if ((sb0 > 0 && sb1 > 0 && sb2 > 0) || (sb0 < 0 && sb1 < 0 && sb2 < 0)) return false;
  const std::array<const Vec*, 3> A{&a0, &a1, &a2}, B{&b0, &b1, &b2};
  for (int e = 0; e < 3; ++e) {
    if (segment_triangle_intersect(*A[e], *A[(e + 1) % 3], b0, b1, b2)) return true;
    if (segment_triangle_intersect(*B[e], *B[(e + 1) % 3], a0, a1, a2)) return true;
  }
  return false;
}

std::vector<Vec> triangle_intersection_points(const Vec& a0, const Vec& a1, const Vec& a2,
                                              const Vec& b0, const Vec& b1, const Vec& b2) {
  std::vector<Vec> pts;
  if (!triangles_intersect(a0, a1, a2, b0, b1, b2)) return pts;
  const std::array<Vec, 3> A{a0, a1, a2}, B{b0, b1, b2};
  auto edges_vs = [&](const std::array<Vec, 3>& T, const std::array<Vec, 3>& U) {
    for (int e = 0; e < 3; ++e) {
      const Vec& s0 = T[e];
      const Vec& s1 = T[(e + 1) % 3];
      if (!segment_triangle_intersect(s0, s1, U[0], U[1], U[2])) continue;
      const int o0 = orient3d(U[0], U[1], U[2], s0), o1 = orient3d(U[0], U[1], U[2], s1);
      if (o0 != 0 || o1 != 0) {
        // One crossing point: solve along the edge with floating-point distances.
        const Vec n = (U[1] - U[0]).cross(U[2] - U[0]);
        const double d0 = n.dot(s0 - U[0]), d1 = n.dot(s1 - U[0]);
        const double t = (d0 == d1) ? 0.0 : std::clamp(d0 / (d0 - d1), 0.0, 1.0);
        pts.push_back(s0 + t * (s1 - s0));
        continue;
      }
      // Edge in the plane of U: its endpoints inside U, and its crossings with U's edges.
      const int k = projection_axis(U[0], U[1], U[2]);
      if (k < 0) {
        pts.push_back(s0);  // degenerate U: a representative shared point is enough here
        continue;
      }
      for (const Vec* s : {&s0, &s1})
        if (point_in_triangle_k(k, *s, U[0], U[1], U[2])) pts.push_back(*s);
      const int u = (k + 1) % 3, v = (k + 2) % 3;
      for (int f = 0; f < 3; ++f) {
        const Vec& c = U[f];
        const Vec& d = U[(f + 1) % 3];
        if (!segments_meet_k(k, s0, s1, c, d)) continue;
        const double den = (s1[u] - s0[u]) * (d[v] - c[v]) - (s1[v] - s0[v]) * (d[u] - c[u]);
        if (den == 0.0) {  // collinear overlap: endpoints within the other segment
          for (const Vec* x : {&c, &d})
            if (on_segment_k(k, s0, s1, *x)) pts.push_back(*x);
          continue;
        }
        const double t = std::clamp(
            ((c[u] - s0[u]) * (d[v] - c[v]) - (c[v] - s0[v]) * (d[u] - c[u])) / den, 0.0, 1.0);
        pts.push_back(s0 + t * (s1 - s0));
      }
    }
  };
  edges_vs(A, B);
  edges_vs(B, A);
  return pts;
}

}  // namespace icd::collision
