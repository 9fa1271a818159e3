#include <icd/mesh/pipeline/hausdorff.hpp>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/pipeline/cgal_convert.hpp>

namespace icd::mesh {
namespace {

using detail::Kernel;
using detail::Point;
using Triangle = Kernel::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Point point(const SurfaceMesh& m, int v) { return {m.V(v, 0), m.V(v, 1), m.V(v, 2)}; }

/// Largest distance from the samples of `from` to the surface `to`.
double one_sided(const SurfaceMesh& from, const SurfaceMesh& to) {
  std::vector<Triangle> tris;
  tris.reserve(static_cast<std::size_t>(to.F.rows()));
  for (int f = 0; f < to.F.rows(); ++f)
    tris.emplace_back(point(to, to.F(f, 0)), point(to, to.F(f, 1)), point(to, to.F(f, 2)));
  Tree tree(tris.begin(), tris.end());
  tree.accelerate_distance_queries();
  double d2 = 0.0;
  const auto probe = [&](const Point& p) { d2 = std::max(d2, tree.squared_distance(p)); };
  // Only vertices used by faces are samples (a tet mesh's interior nodes are not).
  for (int f = 0; f < from.F.rows(); ++f) {
    const Point a = point(from, from.F(f, 0)), b = point(from, from.F(f, 1)),
                c = point(from, from.F(f, 2));
    probe(a);
    probe(b);
    probe(c);
    probe(CGAL::centroid(a, b, c));
    // Each interior edge is shared by two faces; probing it twice is harmless.
    probe(CGAL::midpoint(a, b));
    probe(CGAL::midpoint(b, c));
    probe(CGAL::midpoint(c, a));
  }
  return std::sqrt(d2);
}

}  // namespace

double approximate_hausdorff_distance(const SurfaceMesh& a, const SurfaceMesh& b) {
  if (a.F.rows() == 0 || b.F.rows() == 0)
    throw InputError("approximate_hausdorff_distance: empty surface");
  return std::max(one_sided(a, b), one_sided(b, a));
}

double approximate_one_sided_distance(const SurfaceMesh& from, const SurfaceMesh& to) {
  if (from.F.rows() == 0 || to.F.rows() == 0)
    throw InputError("approximate_one_sided_distance: empty surface");
  return one_sided(from, to);
}

}  // namespace icd::mesh
