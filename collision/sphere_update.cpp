#include <icd/collision/sphere_update.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>
#include <vector>

#include <icd/mesh/core/error.hpp>

namespace icd::collision {

void update_spheres(SphereTree& tree, const Eigen::Ref<const MatX3d>& coarse_rest,
                    const Eigen::Ref<const MatX3d>& coarse_positions,
                    const SphereUpdateOptions& options) {
  const int n = tree.num_nodes();
  if (tree.assoc_offset.size() != static_cast<std::size_t>(n) + 1)
    throw ParameterError(
        "update_spheres: the tree has no coarse-node association (call associate_*_nodes first)");
  if (coarse_rest.rows() != coarse_positions.rows())
    throw ParameterError("update_spheres: coarse_rest has " + std::to_string(coarse_rest.rows()) +
                         " rows, coarse_positions " + std::to_string(coarse_positions.rows()));
  if (!(options.margin >= 0.0)) throw ParameterError("SphereUpdateOptions::margin must be >= 0");
  const double* X = coarse_rest.data();
  const double* x = coarse_positions.data();
  const int32_t* off = tree.assoc_offset.data();
  const int32_t* nodes = tree.assoc_nodes.data();
  const double* rest_dist = tree.assoc_rest_dist.data();
  const bool ratio = options.mode == SphereUpdateMode::PaperRatio;
  // The displacements u_j = x_j - X_j, once per coarse node (the spheres share
  // nodes): the same values the per-sphere sums would form, read from one
  // packed array.
  thread_local std::vector<double> t_u;
  t_u.resize(static_cast<std::size_t>(3 * coarse_rest.rows()));
  double* u = t_u.data();
  for (Eigen::Index j = 0; j < 3 * coarse_rest.rows(); ++j) u[j] = x[j] - X[j];
  const auto rows = static_cast<uint32_t>(coarse_rest.rows());
  bool bad_index = false;  // an associated node index out of range (checked once, below)
  double check = 0.0;
  for (int i = 0; i < n; ++i) {
    const int32_t b = off[i], e = off[i + 1];
    const Sphere rs = tree.rest_spheres[i];
    Sphere& s = tree.spheres[i];
    if (b == e) {  // no associated node: nothing to follow (validate-time precondition)
      s = rs;
      s.r += options.margin;
      continue;
    }
    double ux = 0, uy = 0, uz = 0;
    for (int32_t k = b; k < e; ++k) {
      const int32_t j = nodes[k];
      bad_index |= static_cast<uint32_t>(j) >= rows;
      ux += u[3 * j];
      uy += u[3 * j + 1];
      uz += u[3 * j + 2];
    }
    const double inv = 1.0 / (e - b);
    ux *= inv;
    uy *= inv;
    uz *= inv;
    const double cx = rs.x + ux, cy = rs.y + uy, cz = rs.z + uz;
    double r;
    if (ratio) {
      double lambda2 = 0.0;
      bool any = false;
      for (int32_t k = b; k < e; ++k) {
        const int32_t j = nodes[k];
        const double d0 = rest_dist[k];
        if (d0 <= 1e-12 * (rs.r + 1e-300)) continue;  // node at the centre: no ratio
        const double dx = x[3 * j] - cx, dy = x[3 * j + 1] - cy, dz = x[3 * j + 2] - cz;
        lambda2 = std::max(lambda2, (dx * dx + dy * dy + dz * dz) / (d0 * d0));
        any = true;
      }
      r = (any ? std::sqrt(lambda2) : 1.0) * rs.r + options.margin;
    } else {
      double dev2 = 0.0;
      for (int32_t k = b; k < e; ++k) {
        const int32_t j = nodes[k];
        const double dx = u[3 * j] - ux, dy = u[3 * j + 1] - uy, dz = u[3 * j + 2] - uz;
        dev2 = std::max(dev2, dx * dx + dy * dy + dz * dz);
      }
      r = rs.r + std::sqrt(dev2) + options.margin;
    }
    s = {cx, cy, cz, r};
    check += s.x + s.y + s.z + s.r;
  }
  assert(!bad_index && "update_spheres: an associated coarse node index is out of range");
  (void)bad_index;
  if (!std::isfinite(check)) {
    for (int i = 0; i < n; ++i) {
      const Sphere& s = tree.spheres[i];
      if (!std::isfinite(s.x + s.y + s.z + s.r))
        throw NumericalError("update_spheres: sphere " + std::to_string(i) +
                             " is not finite after the update (non-finite coarse node positions?)");
    }
  }
}

void enclose_children(SphereTree& t) {
  for (int i = t.num_nodes() - 1; i >= 0; --i) {
    Sphere& s = t.spheres[i];
    for (int c = t.first_child[i]; c >= 0 && c < t.first_child[i] + t.child_count[i]; ++c) {
      const Sphere& k = t.spheres[c];
      s.r = std::max(s.r, (k.center() - s.center()).norm() + k.r);
    }
  }
}

}  // namespace icd::collision
