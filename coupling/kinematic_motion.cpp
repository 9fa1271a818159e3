#include <icd/coupling/kinematic_motion.hpp>

#include <cmath>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::coupling {

KeyframeMotion::KeyframeMotion(std::vector<Keyframe> keys, const Eigen::Vector3d& pivot)
    : m_keys(std::move(keys)), m_pivot(pivot) {
  if (m_keys.empty()) throw ParameterError("keyframes: need at least one key");
  if (!m_pivot.allFinite()) throw ParameterError("keyframes: the pivot must be finite");
  for (size_t k = 0; k < m_keys.size(); ++k) {
    Keyframe& key = m_keys[k];
    const std::string field = "keyframes[" + std::to_string(k) + "]";
    if (!std::isfinite(key.t)) throw ParameterError(field + ".t: must be finite");
    if (k > 0 && !(key.t > m_keys[k - 1].t))
      throw ParameterError(field + ".t: times must increase strictly, got " +
                           std::to_string(key.t) + " after " + std::to_string(m_keys[k - 1].t));
    if (!key.position.allFinite()) throw ParameterError(field + ".position: must be finite");
    const double n = key.rotation.norm();
    if (!std::isfinite(n) || !(n > 0))
      throw ParameterError(field + ".rotation: must be a finite non-zero quaternion");
    key.rotation.normalize();
  }
}

Keyframe KeyframeMotion::at(double t) const {
  if (t <= m_keys.front().t) return m_keys.front();
  if (t >= m_keys.back().t) return m_keys.back();
  size_t k = 1;
  while (m_keys[k].t < t) ++k;  // m_keys[k - 1].t < t <= m_keys[k].t
  const Keyframe &a = m_keys[k - 1], &b = m_keys[k];
  const double s = (t - a.t) / (b.t - a.t);
  Keyframe out;
  out.t = t;
  out.position = (1 - s) * a.position + s * b.position;
  out.rotation = a.rotation.slerp(s, b.rotation);  // Eigen takes the shorter arc
  return out;
}

RigidPose KeyframeMotion::pose(double t) const {
  const Keyframe k = at(t);
  RigidPose p;
  p.rotation = k.rotation;
  p.translation = k.position - (k.rotation * m_pivot);
  return p;
}

MotionFunction KeyframeMotion::function() const {
  return [m = *this](double t) { return m.pose(t); };
}

}  // namespace icd::coupling
