#pragma once
/// Exact orientation predicates on double coordinates: a floating-point filter
/// with a fallback to exact expansion arithmetic (Shewchuk's technique), so
/// the sign is always the sign of the exact determinant.
#include <Eigen/Core>

namespace icd::collision {

/// Sign (-1, 0, +1) of det[b - a; c - a; d - a] (3x3, rows), computed exactly:
/// positive when d lies on the side of plane (a, b, c) that (b-a) x (c-a) points to.
int orient3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
             const Eigen::Vector3d& d);

/// Sign of the 2D orientation det[b - a; c - a] of points (x, y), computed exactly:
/// positive when a, b, c turn counter-clockwise.
int orient2d(double ax, double ay, double bx, double by, double cx, double cy);

}  // namespace icd::collision
