#include <icd/mesh/spheres/triangle_bvh.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/triangle_geometry.hpp>

namespace icd::mesh {

TriangleBvh::TriangleBvh(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F) {
  if (V.rows() == 0 || F.rows() == 0) {
    throw InputError("TriangleBvh: empty mesh (" + std::to_string(V.rows()) + " vertices, " +
                     std::to_string(F.rows()) + " faces)");
  }
  const auto nf = static_cast<size_t>(F.rows());
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (F(f, k) < 0 || F(f, k) >= V.rows()) {
        throw InputError("TriangleBvh: face " + std::to_string(f) +
                         " has out-of-range vertex index " + std::to_string(F(f, k)));
      }
    }
  }
  m_order.resize(nf);
  std::iota(m_order.begin(), m_order.end(), 0);
  m_centroid.resize(nf);
  std::vector<Eigen::Vector3d> corners(3 * nf);
  for (size_t f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k)
      corners[3 * f + static_cast<size_t>(k)] = V.row(F(static_cast<Eigen::Index>(f), k));
    m_centroid[f] = (corners[3 * f] + corners[3 * f + 1] + corners[3 * f + 2]) / 3.0;
  }
  m_corner = std::move(corners);  // indexed by row of F while building
  m_nodes.reserve(nf);
  build(0, static_cast<int>(nf), 0);
  std::vector<Eigen::Vector3d> ordered(3 * nf);
  for (size_t i = 0; i < nf; ++i) {
    for (size_t k = 0; k < 3; ++k)
      ordered[3 * i + k] = m_corner[3 * static_cast<size_t>(m_order[i]) + k];
  }
  m_corner = std::move(ordered);
  m_centroid.clear();
  m_centroid.shrink_to_fit();
}

int TriangleBvh::build(int begin, int end, int depth) {
  const int index = static_cast<int>(m_nodes.size());
  m_nodes.push_back(Node{});
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (int i = begin; i < end; ++i) {
    for (size_t k = 0; k < 3; ++k) {
      const Eigen::Vector3d& q =
          m_corner[3 * static_cast<size_t>(m_order[static_cast<size_t>(i)]) + k];
      lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    }
  }
  for (int k = 0; k < 3; ++k) m_nodes[static_cast<size_t>(index)].lo[k] = lo[k];
  for (int k = 0; k < 3; ++k) m_nodes[static_cast<size_t>(index)].hi[k] = hi[k];
  if (end - begin <= 4 || depth > 60) {
    m_nodes[static_cast<size_t>(index)].first = begin;
    m_nodes[static_cast<size_t>(index)].count = end - begin;
    m_nodes[static_cast<size_t>(index)].right = -1;
    return index;
  }
  int axis = 0;
  const Eigen::Vector3d extent = hi - lo;
  if (extent[1] > extent[axis]) axis = 1;
  if (extent[2] > extent[axis]) axis = 2;
  const int mid = begin + (end - begin) / 2;
  std::nth_element(m_order.begin() + begin, m_order.begin() + mid, m_order.begin() + end,
                   [&](int a, int b) {
                     const double ca = m_centroid[static_cast<size_t>(a)][axis];
                     const double cb = m_centroid[static_cast<size_t>(b)][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  const int left = build(begin, mid, depth + 1);
  const int right = build(mid, end, depth + 1);
  m_nodes[static_cast<size_t>(index)].first = left;
  m_nodes[static_cast<size_t>(index)].count = 0;
  m_nodes[static_cast<size_t>(index)].right = right;
  return index;
}

TriangleBvh::Hit TriangleBvh::closest(const Eigen::Vector3d& p) const {
  auto box_distance2 = [&](const Node& n) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double e = std::max({n.lo[k] - p[k], p[k] - n.hi[k], 0.0});
      d2 += e * e;
    }
    return d2;
  };
  Hit hit;
  hit.squared_distance = std::numeric_limits<double>::infinity();
  // Depth-first, nearer child first; a stack of (node, squared lower bound)
  // (depth <= 61, at most two entries per level).
  std::pair<int, double> stack[128];
  int top = 0;
  stack[top++] = {0, box_distance2(m_nodes.front())};
  while (top > 0) {
    const auto [index, bound] = stack[--top];
    if (bound >= hit.squared_distance) continue;
    const Node& n = m_nodes[static_cast<size_t>(index)];
    if (n.count > 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const size_t t = 3 * static_cast<size_t>(i);
        const Eigen::Vector3d q =
            closest_point_on_triangle(p, m_corner[t], m_corner[t + 1], m_corner[t + 2]);
        const double d2 = (q - p).squaredNorm();
        if (d2 < hit.squared_distance) {
          hit.squared_distance = d2, hit.point = q, hit.face = m_order[static_cast<size_t>(i)];
        }
      }
      continue;
    }
    const int left = n.first, right = n.right;
    const double dl = box_distance2(m_nodes[static_cast<size_t>(left)]);
    const double dr = box_distance2(m_nodes[static_cast<size_t>(right)]);
    if (dl <= dr) {
      if (dr < hit.squared_distance) stack[top++] = {right, dr};
      if (dl < hit.squared_distance) stack[top++] = {left, dl};
    } else {
      if (dl < hit.squared_distance) stack[top++] = {left, dl};
      if (dr < hit.squared_distance) stack[top++] = {right, dr};
    }
  }
  return hit;
}

double TriangleBvh::distance(const Eigen::Vector3d& p) const {
  return std::sqrt(closest(p).squared_distance);
}

}  // namespace icd::mesh
