#include <icd/collision/octree_tree.hpp>

#include <array>
#include <cassert>
#include <cmath>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::collision {
namespace {

// A convex polygon: a triangle clipped by at most 6 planes has at most 9 vertices.
struct Polygon {
  std::array<Eigen::Vector3d, 12> p;
  int n = 0;
  Polygon() {
    for (auto& q : p) q.setZero();
  }
};

// Keeps the part of `in` with sign * (x_axis - value) >= 0 (closed half-space).
Polygon clip(const Polygon& in, int axis, double value, double sign) {
  Polygon out;
  for (int i = 0; i < in.n; ++i) {
    const Eigen::Vector3d& a = in.p[i];
    const Eigen::Vector3d& b = in.p[(i + 1) % in.n];
    const double da = sign * (a[axis] - value), db = sign * (b[axis] - value);
    const bool ina = da >= 0.0, inb = db >= 0.0;
    assert(out.n + 2 <= static_cast<int>(out.p.size()));
    if (ina) out.p[out.n++] = a;
    if (ina != inb) {
      const double t = da / (da - db);
      Eigen::Vector3d q = a + t * (b - a);
      q[axis] = value;  // exactly on the plane
      out.p[out.n++] = q;
    }
  }
  return out;
}

struct Cell {
  Eigen::Vector3d lo;
  double size = 0;
  std::vector<Polygon> parts;
};

Sphere enclosing_sphere(const std::vector<Polygon>& parts, double extra) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const Polygon& poly : parts)
    for (int i = 0; i < poly.n; ++i) {
      lo = lo.cwiseMin(poly.p[i]);
      hi = hi.cwiseMax(poly.p[i]);
    }
  const Eigen::Vector3d c = 0.5 * (lo + hi);
  double r2 = 0.0;
  for (const Polygon& poly : parts)
    for (int i = 0; i < poly.n; ++i) r2 = std::max(r2, (poly.p[i] - c).squaredNorm());
  return {c.x(), c.y(), c.z(), std::sqrt(r2) + extra};
}

}  // namespace

SphereTree build_octree_tree(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F,
                             const OctreeTreeOptions& options) {
  if (options.levels < 1)
    throw ParameterError("OctreeTreeOptions::levels must be >= 1, got " +
                         std::to_string(options.levels));
  if (!(options.margin >= 0.0)) throw ParameterError("OctreeTreeOptions::margin must be >= 0");
  if (!(options.relative_margin >= 0.0))
    throw ParameterError("OctreeTreeOptions::relative_margin must be >= 0");
  if (V.rows() == 0 || F.rows() == 0) throw InputError("build_octree_tree: empty mesh");
  for (int i = 0; i < V.rows(); ++i)
    if (!V.row(i).allFinite())
      throw InputError("build_octree_tree: vertex " + std::to_string(i) +
                       " has a non-finite coordinate");
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) < 0 || F(f, k) >= V.rows())
        throw InputError("build_octree_tree: face " + std::to_string(f) + " has vertex index " +
                         std::to_string(F(f, k)) + " out of range");

  const Eigen::Vector3d vmin = V.colwise().minCoeff().transpose(),
                        vmax = V.colwise().maxCoeff().transpose();
  double side = (vmax - vmin).maxCoeff();
  if (side <= 0.0) side = 1.0;
  side *= 1.0 + 1e-6;
  const Eigen::Vector3d center = 0.5 * (vmin + vmax);
  const double extra = options.margin + options.relative_margin * side;

  Cell root;
  root.lo = center - Eigen::Vector3d::Constant(0.5 * side);
  root.size = side;
  root.parts.reserve(F.rows());
  for (int f = 0; f < F.rows(); ++f) {
    Polygon t;
    t.n = 3;
    for (int k = 0; k < 3; ++k) t.p[k] = V.row(F(f, k)).transpose();
    root.parts.push_back(t);
  }

  SphereTree tree;
  std::vector<int32_t> parent;
  std::vector<Cell> current;
  tree.spheres.push_back(enclosing_sphere(root.parts, extra));
  parent.push_back(-1);
  current.push_back(std::move(root));
  int32_t level_begin = 0;
  for (int level = 1; level < options.levels; ++level) {
    std::vector<Cell> next;
    for (std::size_t ci = 0; ci < current.size(); ++ci) {
      const Cell& cell = current[ci];
      const double h = 0.5 * cell.size;
      for (int oct = 0; oct < 8; ++oct) {
        Cell child;
        child.size = h;
        child.lo = cell.lo + h * Eigen::Vector3d(oct & 1, (oct >> 1) & 1, (oct >> 2) & 1);
        for (const Polygon& poly : cell.parts) {
          Polygon q = poly;
          for (int axis = 0; axis < 3 && q.n > 0; ++axis) {
            q = clip(q, axis, child.lo[axis], 1.0);
            if (q.n > 0) q = clip(q, axis, child.lo[axis] + h, -1.0);
          }
          if (q.n > 0) child.parts.push_back(q);
        }
        if (child.parts.empty()) continue;
        tree.spheres.push_back(enclosing_sphere(child.parts, extra));
        parent.push_back(level_begin + static_cast<int32_t>(ci));
        next.push_back(std::move(child));
      }
    }
    if (next.empty()) break;
    level_begin += static_cast<int32_t>(current.size());
    current.swap(next);
  }
  build_topology(tree, parent);
  tree.rest_spheres = tree.spheres;
  return tree;
}

}  // namespace icd::collision
