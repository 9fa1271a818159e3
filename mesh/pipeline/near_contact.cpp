#include <icd/mesh/pipeline/near_contact.hpp>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>

#include <algorithm>
#include <vector>

#include <icd/mesh/core/union_find.hpp>
#include <icd/mesh/pipeline/cgal_convert.hpp>

namespace icd::mesh {
namespace {

using detail::Kernel;
using detail::Point;
using Triangle = Kernel::Triangle_3;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, std::vector<Triangle>::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

}  // namespace

ComponentGap closest_component_gap(const SurfaceMesh& surface, double within) {
  ComponentGap gap;
  const int nv = static_cast<int>(surface.V.rows()), nf = static_cast<int>(surface.F.rows());
  UnionFind parts(nv);
  for (int f = 0; f < nf; ++f)
    for (int k = 1; k < 3; ++k) parts.unite(surface.F(f, 0), surface.F(f, k));
  // Components numbered in the order of their first face; each with its
  // faces, vertices and bounding box.
  std::vector<int> id(static_cast<std::size_t>(nv), -1);
  std::vector<std::vector<int>> faces, verts;
  for (int f = 0; f < nf; ++f) {
    int& c = id[static_cast<std::size_t>(parts.find(surface.F(f, 0)))];
    if (c < 0) {
      c = static_cast<int>(faces.size());
      faces.emplace_back();
      verts.emplace_back();
    }
    faces[static_cast<std::size_t>(c)].push_back(f);
  }
  for (int v = 0; v < nv; ++v) {
    const int c = id[static_cast<std::size_t>(parts.find(v))];
    if (c >= 0) verts[static_cast<std::size_t>(c)].push_back(v);
  }
  gap.components = static_cast<int>(faces.size());
  if (gap.components < 2) return gap;
  std::vector<Eigen::RowVector3d> lo(faces.size()), hi(faces.size());
  for (std::size_t c = 0; c < faces.size(); ++c) {
    lo[c] = hi[c] = surface.V.row(verts[c].front());
    for (int v : verts[c]) {
      lo[c] = lo[c].cwiseMin(surface.V.row(v));
      hi[c] = hi[c].cwiseMax(surface.V.row(v));
    }
  }
  const auto point = [&](int v) {
    return Point(surface.V(v, 0), surface.V(v, 1), surface.V(v, 2));
  };
  double best2 = INFINITY;
  std::vector<char> close(static_cast<std::size_t>(nv), 0);
  // Pruned by `within` when it is finite (every vertex within it is
  // counted), else by the best distance so far.
  const auto reach = [&] { return std::isfinite(within) ? within : std::sqrt(best2); };
  for (std::size_t c = 0; c < faces.size(); ++c) {
    std::vector<Triangle> tris;
    tris.reserve(faces[c].size());
    for (int f : faces[c])
      tris.emplace_back(point(surface.F(f, 0)), point(surface.F(f, 1)), point(surface.F(f, 2)));
    Tree tree(tris.begin(), tris.end());
    tree.accelerate_distance_queries();
    // Vertices of the other components within reach() of this component's
    // bounding box.
    for (std::size_t d = 0; d < faces.size(); ++d) {
      if (d == c) continue;
      if (((lo[d].array() - hi[c].array()) > reach()).any() ||
          ((lo[c].array() - hi[d].array()) > reach()).any())
        continue;
      for (int v : verts[d]) {
        const Eigen::RowVector3d p = surface.V.row(v);
        const double r = reach();
        if (((p.array() - hi[c].array()) > r).any() || ((lo[c].array() - p.array()) > r).any())
          continue;
        const Point q = tree.closest_point(point(v));
        const double d2 = CGAL::squared_distance(q, point(v));
        if (d2 <= within * within) close[static_cast<std::size_t>(v)] = 1;
        if (d2 < best2) {
          best2 = d2;
          gap.first = static_cast<int>(std::min(c, d));
          gap.second = static_cast<int>(std::max(c, d));
          gap.where = {0.5 * (p[0] + q.x()), 0.5 * (p[1] + q.y()), 0.5 * (p[2] + q.z())};
        }
      }
    }
  }
  gap.distance = std::sqrt(best2);
  gap.close_vertices = static_cast<int>(std::count(close.begin(), close.end(), 1));
  return gap;
}

}  // namespace icd::mesh
