#include <icd/mesh/core/triangle_geometry.hpp>

#include <algorithm>

namespace icd {

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;  // vertex region a
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;  // vertex region b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {  // edge region ab
    const double den = d1 - d3;
    return den > 0 ? Eigen::Vector3d(a + (d1 / den) * ab) : a;
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;  // vertex region c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {  // edge region ac
    const double den = d2 - d6;
    return den > 0 ? Eigen::Vector3d(a + (d2 / den) * ac) : a;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {  // edge region bc
    const double den = (d4 - d3) + (d5 - d6);
    return den > 0 ? Eigen::Vector3d(b + ((d4 - d3) / den) * (c - b)) : b;
  }
  const double sum = va + vb + vc;
  if (!(sum > 0)) {
    // Degenerate (flat) triangle: the nearest of its three edges.
    auto on_segment = [&](const Eigen::Vector3d& s, const Eigen::Vector3d& t) {
      const Eigen::Vector3d st = t - s;
      const double len2 = st.squaredNorm();
      const double u = len2 > 0 ? std::clamp((p - s).dot(st) / len2, 0.0, 1.0) : 0.0;
      return Eigen::Vector3d(s + u * st);
    };
    Eigen::Vector3d best = on_segment(a, b);
    for (const Eigen::Vector3d& q : {on_segment(b, c), on_segment(c, a)}) {
      if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
    }
    return best;
  }
  const double v = vb / sum, w = vc / sum;  // face region
  return a + v * ab + w * ac;
}

}  // namespace icd
