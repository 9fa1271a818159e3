#pragma once
/// Scripted motion of kinematic (rigid) objects, as a tool or probe in SOFA
/// or a mocap body in MuJoCo: a rigid pose as a function of simulated time,
/// either keyframed (position linear, rotation slerp) or any user function.
/// The World places the object's coarse nodes at pose(t) * rest at the end
/// of every detection/response cycle (see ObjectSetup::motion).
#include <functional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace icd::coupling {

/// A rigid transform of an object's rest (placed) coarse nodes:
/// x = rotation * x_rest + translation.
struct RigidPose {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();

  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return rotation * x + translation; }
};

/// The pose of a kinematic object at simulated time t (s).
using MotionFunction = std::function<RigidPose(double t)>;

/// One key of a keyframed motion: at time t, the pivot point of the object
/// is at `position` and the object is turned by `rotation` (about the pivot,
/// from its rest orientation).
struct Keyframe {
  double t = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

/// A keyframed motion: the pivot moves linearly between keys and the
/// rotation follows the shortest slerp; before the first key the object
/// holds the first key, after the last key it holds the last one.
class KeyframeMotion {
 public:
  /// `keys` sorted by strictly increasing time (at least one), unit-norm
  /// quaternions after normalisation; `pivot` is the point of the rest
  /// object that `position` places (e.g. its bounding-box centre). Throws
  /// ParameterError naming the key for unsorted times, non-finite values or
  /// a zero quaternion.
  KeyframeMotion(std::vector<Keyframe> keys, const Eigen::Vector3d& pivot);

  /// Pivot position and rotation at time t.
  Keyframe at(double t) const;
  /// The rigid pose at time t: x = R (x_rest - pivot) + position.
  RigidPose pose(double t) const;
  /// As a MotionFunction (copies the keys).
  MotionFunction function() const;

  const std::vector<Keyframe>& keys() const { return m_keys; }
  const Eigen::Vector3d& pivot() const { return m_pivot; }

 private:
  std::vector<Keyframe> m_keys;
  Eigen::Vector3d m_pivot;
};

}  // namespace icd::coupling
