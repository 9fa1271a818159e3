#pragma once
/// Static analytic obstacles (not in the paper): a half-space (plane) or an
/// oriented box that never moves, as MuJoCo's plane and box geoms or a
/// floor in a game engine. Deformable objects are kept out of them by
/// projection, not by a penalty: after each cycle's FEM step, every dense
/// surface vertex found inside an obstacle is moved out along the
/// obstacle's normal by moving the three coarse nodes of its rigid link (a
/// common translation of a link's nodes moves its vertex by exactly that
/// translation), and those nodes lose their velocity into the obstacle
/// (inelastic, frictionless contact). Nodes of vertices resting on an
/// obstacle (within World::kObstacleContact) are supported during the next
/// cycle: the obstacle cancels the inward normal part of their total force,
/// so they do not sink and the projection has almost nothing to do; cycles
/// near an obstacle last at most World::kObstacleCycle. Whatever energy the
/// projection and the support still add (stored elastic energy, lift
/// against gravity, work of a support held over a cycle while the node
/// lifts off) is taken back from the object's kinetic energy, so the
/// obstacles never are a source of energy. A penalty would need a stiffness
/// that holds the object's weight within the tolerance (4e6 N/m for a 4 kg
/// ball under 1000 m/s^2 within 1 mm), far beyond what the cycled explicit
/// response keeps stable; the projection holds at any load.
#include <Eigen/Core>

namespace icd::coupling {

/// A static obstacle.
struct Obstacle {
  enum class Type { Plane, Box };
  Type type = Type::Plane;
  /// Plane: a point of the plane; box: its centre (m).
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// Plane: the outward normal (the free side; normalised by validate()).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  /// Box: half side lengths along its axes (m, > 0).
  Eigen::Vector3d half_extents = Eigen::Vector3d::Constant(0.5);
  /// Box: its axes as columns (a rotation matrix).
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();

  /// Signed distance of p to the obstacle's surface (m): > 0 outside, < 0
  /// inside; *n (if given) the outward normal of the nearest face for a point
  /// inside (the direction that leaves the obstacle fastest), of the plane
  /// for a plane.
  double signed_distance(const Eigen::Vector3d& p, Eigen::Vector3d* n = nullptr) const;
  /// A lower bound of the signed distance over the axis-aligned box [lo, hi].
  double lower_bound(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) const;
  /// Smallest thickness of the obstacle (m; infinity for a plane).
  double thickness() const;
};

/// Throws ParameterError naming `field` for a zero or non-finite normal, a
/// non-positive or non-finite box side, or box axes that are not a rotation;
/// normalises a plane's normal.
void validate(Obstacle& obstacle, const char* field);

}  // namespace icd::coupling
