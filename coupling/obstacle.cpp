#include <icd/coupling/obstacle.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::coupling {

double Obstacle::signed_distance(const Eigen::Vector3d& p, Eigen::Vector3d* n) const {
  if (type == Type::Plane) {
    if (n) *n = normal;
    return normal.dot(p - point);
  }
  const Eigen::Vector3d q = axes.transpose() * (p - point);  // in the box frame
  const Eigen::Vector3d d = q.cwiseAbs() - half_extents;     // > 0: outside that slab
  if (d.maxCoeff() > 0) {  // outside: distance to the box
    const Eigen::Vector3d out = d.cwiseMax(0.0);
    if (n) {
      Eigen::Vector3d local = out.cwiseProduct(q.cwiseSign());
      *n = axes * local.normalized();
    }
    return out.norm();
  }
  int k = 0;  // inside: leave through the nearest face
  d.maxCoeff(&k);
  if (n) *n = axes.col(k) * (q[k] >= 0 ? 1.0 : -1.0);
  return d[k];
}

double Obstacle::lower_bound(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) const {
  if (type == Type::Plane) {
    double m = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d x(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(),
                              c & 4 ? hi.z() : lo.z());
      m = std::min(m, normal.dot(x - point));
    }
    return m;
  }
  // Box: the gap between the box and the bounding box of [lo, hi] seen in the
  // box frame (a lower bound of the distance); <= 0 when they may meet.
  const Eigen::Vector3d c = axes.transpose() * (0.5 * (lo + hi) - point);
  const Eigen::Vector3d e = axes.transpose().cwiseAbs() * (0.5 * (hi - lo));
  const Eigen::Vector3d gap = c.cwiseAbs() - e - half_extents;
  return gap.maxCoeff();
}

double Obstacle::thickness() const {
  return type == Type::Plane ? std::numeric_limits<double>::infinity()
                             : 2 * half_extents.minCoeff();
}

void validate(Obstacle& o, const char* field) {
  const std::string f(field);
  if (o.type == Obstacle::Type::Plane) {
    if (!o.normal.allFinite() || !(o.normal.norm() > 0))
      throw ParameterError(f + ".normal: must be a finite non-zero vector");
    o.normal.normalize();
  } else {
    if (!o.half_extents.allFinite() || !(o.half_extents.minCoeff() > 0))
      throw ParameterError(f + ".extent: sides must be positive and finite");
    if (!o.axes.allFinite() ||
        !(o.axes.transpose() * o.axes).isApprox(Eigen::Matrix3d::Identity(), 1e-9))
      throw ParameterError(f + ".rotation: the box axes must be a rotation");
  }
  if (!o.point.allFinite()) throw ParameterError(f + ".point: must be finite");
}

}  // namespace icd::coupling
