#include <icd/mesh/core/mesh_stats.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <numeric>
#include <string>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/union_find.hpp>

namespace icd {

SurfaceStats compute_surface_stats(const SurfaceMesh& mesh) {
  const MatX3d& V = mesh.V;
  const MatX3i& F = mesh.F;
  const auto nv = static_cast<int>(V.rows());
  const auto nf = static_cast<int>(F.rows());
  if (!V.allFinite())
    throw ParameterError("compute_surface_stats: V has a NaN or infinite coordinate");
  if (nf > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= nv))
    throw ParameterError("compute_surface_stats: F has an index outside [0, " + std::to_string(nv) +
                         ")");
  SurfaceStats s;
  s.vertices = nv;
  s.faces = nf;
  if (nv > 0) {
    s.bbox_min = V.colwise().minCoeff().transpose();
    s.bbox_max = V.colwise().maxCoeff().transpose();
  }

  // Area, volume, degenerate faces; directed half-edges keyed by (min, max).
  struct HalfEdge {
    uint64_t key;
    bool forward;  // traversed from the smaller to the larger index
  };
  std::vector<HalfEdge> half(static_cast<size_t>(3) * nf);
  std::vector<char> referenced(nv, 0);
  UnionFind components(nv);
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    s.area += 0.5 * n.norm();
    s.volume += a.dot(b.cross(c)) / 6.0;
    const double longest =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    const bool repeated = F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 2) == F(f, 0);
    if (repeated || n.norm() <= 1e-12 * longest) ++s.degenerate_faces;
    for (int k = 0; k < 3; ++k) {
      const int i = F(f, k), j = F(f, (k + 1) % 3);
      const auto lo = static_cast<uint64_t>(std::min(i, j)),
                 hi = static_cast<uint64_t>(std::max(i, j));
      half[3 * f + k] = {lo << 32 | hi, i < j};
      referenced[i] = 1;
      components.unite(i, j);
    }
  }
  std::sort(half.begin(), half.end(),
            [](const HalfEdge& x, const HalfEdge& y) { return x.key < y.key; });
  for (size_t i = 0; i < half.size();) {
    size_t j = i;
    int forward = 0;
    while (j < half.size() && half[j].key == half[i].key) forward += half[j++].forward ? 1 : 0;
    const auto count = static_cast<int>(j - i);
    ++s.edges;
    if (count == 1) ++s.boundary_edges;
    if (count > 2) ++s.nonmanifold_edges;
    // A self-loop edge (i == i) has forward == 0 and count 1 or more; ignore it here.
    if (count == 2 && forward != 1 && (half[i].key >> 32) != (half[i].key & 0xffffffffu))
      ++s.inconsistent_edges;
    i = j;
  }
  for (int i = 0; i < nv; ++i) {
    if (!referenced[i])
      ++s.unreferenced_vertices;
    else if (components.find(i) == i)
      ++s.components;
  }

  // Exact duplicates: sort indices by position, compare neighbours.
  std::vector<int> order(nv);
  std::iota(order.begin(), order.end(), 0);
  const auto less = [&](int x, int y) {
    for (int c = 0; c < 3; ++c)
      if (V(x, c) != V(y, c)) return V(x, c) < V(y, c);
    return false;
  };
  std::sort(order.begin(), order.end(), less);
  for (int k = 1; k < nv; ++k)
    if (!less(order[k - 1], order[k])) ++s.duplicate_vertices;

  s.euler_characteristic = s.vertices - s.edges + s.faces;
  return s;
}

}  // namespace icd
