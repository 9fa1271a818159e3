#include "experiments/studies/spheretree/approach.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>

#include <icd/mesh/core/error.hpp>

namespace icd::experiments {

using collision::Sphere;
using collision::SphereTree;

ApproachPose RandomApproachPoses::next() {
  ApproachPose pose;
  // Drawn last component first, each draw sequenced: the order GCC gave
  // the unsequenced constructor arguments of the first version, whose poses
  // the committed outputs use; now the same with any compiler.
  const double qz = m_normal(m_rng), qy = m_normal(m_rng), qx = m_normal(m_rng),
               qw = m_normal(m_rng);
  pose.R = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
  const double uz = m_normal(m_rng), uy = m_normal(m_rng), ux = m_normal(m_rng);
  pose.u = Eigen::Vector3d(ux, uy, uz).normalized();
  pose.c = m_centre;
  return pose;
}

double last_leaf_overlap(const SphereTree& a, const SphereTree& b, const ApproachPose& pose) {
  const int la = a.num_levels() - 1, lb = b.num_levels() - 1;
  double last = -std::numeric_limits<double>::infinity();
  for (int j = b.level_offset[lb]; j < b.level_offset[lb + 1]; ++j) {
    const Eigen::Vector3d q = pose.apply(b.spheres[j].center(), 0.0);
    for (int i = a.level_offset[la]; i < a.level_offset[la + 1]; ++i) {
      // |q + t u - p| <= ra + rb: t^2 + 2 t u.(q - p) + |q - p|^2 - R^2 <= 0.
      const Eigen::Vector3d d = q - a.spheres[i].center();
      const double R = a.spheres[i].r + b.spheres[j].r;
      const double half_b = pose.u.dot(d), c = d.squaredNorm() - R * R;
      const double disc = half_b * half_b - c;
      if (disc >= 0) last = std::max(last, -half_b + std::sqrt(disc));
    }
  }
  return last;
}

SphereTree moved(const SphereTree& tree, const ApproachPose& pose, double t) {
  SphereTree m = tree;
  for (Sphere& s : m.spheres) {
    const Eigen::Vector3d c = pose.apply(s.center(), t);
    s.x = c.x(), s.y = c.y(), s.z = c.z();
  }
  return m;
}

Touching find_touching(const std::function<bool(double)>& meets, double start, double step,
                       double tolerance) {
  if (!(step > 0) || !std::isfinite(step))
    throw ParameterError("find_touching: step must be > 0 and finite, got " + std::to_string(step));
  if (!(tolerance > 0) || !std::isfinite(tolerance))
    throw ParameterError("find_touching: tolerance must be > 0 and finite, got " +
                         std::to_string(tolerance));
  Touching out;
  if (meets(start)) return out;
  double hi = start, lo = start - step;
  while (!meets(lo)) hi = lo, lo -= step;
  for (int it = 0; it < 60 && hi - lo > tolerance; ++it) {
    const double mid = 0.5 * (lo + hi);
    (meets(mid) ? lo : hi) = mid;
  }
  out.found = true;
  out.apart = hi;
  out.crossing = lo;
  return out;
}

SelfApproach::SelfApproach(const MatX3d& V, const MatX3i& F)
    : m_V(V), m_F(F), m_tree(V, F), m_moved(V), m_moved_tree(V, F) {}

bool SelfApproach::meets(const ApproachPose& pose, double t) {
  for (Eigen::Index v = 0; v < m_V.rows(); ++v)
    m_moved.row(v) = pose.apply(m_V.row(v).transpose(), t).transpose();
  m_moved_tree.refit(m_moved, m_F);
  return !collision::intersecting_triangle_pairs(m_tree, m_V, m_F, m_moved_tree, m_moved, m_F)
              .empty();
}

}  // namespace icd::experiments
