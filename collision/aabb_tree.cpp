#include <icd/collision/aabb_tree.hpp>

#include <algorithm>
#include <numeric>
#include <string>

#include <icd/collision/triangle_intersection.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::collision {
namespace {

Eigen::Vector3d vtx(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F, int f,
                    int k) {
  return V.row(F(f, k)).transpose();
}

bool boxes_overlap(const AabbTree::Node& a, const AabbTree::Node& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

bool tri_pair(const Eigen::Ref<const MatX3d>& V1, const Eigen::Ref<const MatX3i>& F1, int f,
              const Eigen::Ref<const MatX3d>& V2, const Eigen::Ref<const MatX3i>& F2, int g) {
  return triangles_intersect(vtx(V1, F1, f, 0), vtx(V1, F1, f, 1), vtx(V1, F1, f, 2),
                             vtx(V2, F2, g, 0), vtx(V2, F2, g, 1), vtx(V2, F2, g, 2));
}

}  // namespace

AabbTree::AabbTree(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F,
                   int leaf_size) {
  if (leaf_size < 1) throw ParameterError("AabbTree: leaf_size must be >= 1");
  for (int i = 0; i < V.rows(); ++i)
    if (!V.row(i).allFinite())
      throw InputError("AabbTree: vertex " + std::to_string(i) + " is not finite");
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) < 0 || F(f, k) >= V.rows())
        throw InputError("AabbTree: face " + std::to_string(f) +
                         " has an out-of-range vertex index");
  if (F.rows() == 0) return;
  std::vector<Eigen::Vector3d> centroids(F.rows());
  for (int f = 0; f < F.rows(); ++f)
    centroids[f] = (vtx(V, F, f, 0) + vtx(V, F, f, 1) + vtx(V, F, f, 2)) / 3.0;
  m_order.resize(F.rows());
  std::iota(m_order.begin(), m_order.end(), 0);
  m_nodes.reserve(2 * F.rows() / leaf_size + 2);
  build(centroids, V, F, 0, static_cast<int>(F.rows()), leaf_size);
}

int AabbTree::build(const std::vector<Eigen::Vector3d>& centroids,
                    const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F, int begin,
                    int end, int leaf_size) {
  const int id = static_cast<int>(m_nodes.size());
  m_nodes.emplace_back();
  if (end - begin <= leaf_size) {
    Node& n = m_nodes[id];
    n.begin = begin;
    n.end = end;
    n.lo = Eigen::Vector3d::Constant(INFINITY);
    n.hi = -n.lo;
    for (int k = begin; k < end; ++k)
      for (int c = 0; c < 3; ++c) {
        n.lo = n.lo.cwiseMin(vtx(V, F, m_order[k], c));
        n.hi = n.hi.cwiseMax(vtx(V, F, m_order[k], c));
      }
    return id;
  }
  Eigen::Vector3d clo = Eigen::Vector3d::Constant(INFINITY), chi = -clo;
  for (int k = begin; k < end; ++k) {
    clo = clo.cwiseMin(centroids[m_order[k]]);
    chi = chi.cwiseMax(centroids[m_order[k]]);
  }
  int axis;
  (chi - clo).maxCoeff(&axis);
  const int mid = (begin + end) / 2;
  std::nth_element(m_order.begin() + begin, m_order.begin() + mid, m_order.begin() + end,
                   [&](int x, int y) { return centroids[x][axis] < centroids[y][axis]; });
  const int left = build(centroids, V, F, begin, mid, leaf_size);
  const int right = build(centroids, V, F, mid, end, leaf_size);
  Node& n = m_nodes[id];
  n.left = left;
  n.right = right;
  n.begin = begin;
  n.end = end;
  n.lo = m_nodes[left].lo.cwiseMin(m_nodes[right].lo);
  n.hi = m_nodes[left].hi.cwiseMax(m_nodes[right].hi);
  return id;
}

void AabbTree::refit(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F) {
  // Children have larger indices than their parent (pre-order build).
  for (int id = static_cast<int>(m_nodes.size()) - 1; id >= 0; --id) {
    Node& n = m_nodes[id];
    if (n.left < 0) {
      n.lo = Eigen::Vector3d::Constant(INFINITY);
      n.hi = -n.lo;
      for (int k = n.begin; k < n.end; ++k)
        for (int c = 0; c < 3; ++c) {
          n.lo = n.lo.cwiseMin(vtx(V, F, m_order[k], c));
          n.hi = n.hi.cwiseMax(vtx(V, F, m_order[k], c));
        }
    } else {
      n.lo = m_nodes[n.left].lo.cwiseMin(m_nodes[n.right].lo);
      n.hi = m_nodes[n.left].hi.cwiseMax(m_nodes[n.right].hi);
    }
  }
}

std::vector<std::pair<int, int>> intersecting_triangle_pairs(
    const AabbTree& t1, const Eigen::Ref<const MatX3d>& V1, const Eigen::Ref<const MatX3i>& F1,
    const AabbTree& t2, const Eigen::Ref<const MatX3d>& V2, const Eigen::Ref<const MatX3i>& F2) {
  std::vector<std::pair<int, int>> out;
  if (t1.nodes().empty() || t2.nodes().empty()) return out;
  std::vector<std::pair<int, int>> stack{{0, 0}};
  const auto& n1 = t1.nodes();
  const auto& n2 = t2.nodes();
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    const AabbTree::Node& a = n1[i];
    const AabbTree::Node& b = n2[j];
    if (!boxes_overlap(a, b)) continue;
    const bool la = a.left < 0, lb = b.left < 0;
    if (la && lb) {
      for (int x = a.begin; x < a.end; ++x)
        for (int y = b.begin; y < b.end; ++y) {
          const int f = t1.order()[x], g = t2.order()[y];
          if (tri_pair(V1, F1, f, V2, F2, g)) out.push_back({f, g});
        }
    } else if (lb || (!la && (a.end - a.begin) >= (b.end - b.begin))) {
      stack.push_back({a.left, j});
      stack.push_back({a.right, j});
    } else {
      stack.push_back({i, b.left});
      stack.push_back({i, b.right});
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::pair<int, int>> intersecting_triangle_pairs_brute_force(
    const Eigen::Ref<const MatX3d>& V1, const Eigen::Ref<const MatX3i>& F1,
    const Eigen::Ref<const MatX3d>& V2, const Eigen::Ref<const MatX3i>& F2) {
  std::vector<std::pair<int, int>> out;
  for (int f = 0; f < F1.rows(); ++f)
    for (int g = 0; g < F2.rows(); ++g)
      if (tri_pair(V1, F1, f, V2, F2, g)) out.push_back({f, g});
  return out;
}

}  // namespace icd::collision
