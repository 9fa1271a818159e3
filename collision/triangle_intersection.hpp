#pragma once
/// Exact triangle-triangle intersection test of the dense meshes: the
/// reference the sphere-tree answers are checked against.
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace icd::collision {

/// True when the closed triangles (a0, a1, a2) and (b0, b1, b2) share a point.
/// Exact for every input (touching at a vertex or an edge, coplanar overlap,
/// zero-area triangles): built only on exact orient3d / orient2d signs. Uses
/// the fact that two closed triangles meet iff an edge of one meets the other.
bool triangles_intersect(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1,
                         const Eigen::Vector3d& a2, const Eigen::Vector3d& b0,
                         const Eigen::Vector3d& b1, const Eigen::Vector3d& b2);

/// True when the closed segment [s0, s1] and the closed triangle (p, q, r) meet (exact).
bool segment_triangle_intersect(const Eigen::Vector3d& s0, const Eigen::Vector3d& s1,
                                const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                const Eigen::Vector3d& r);

/// Points of the intersection of two triangles whose convex hull is the
/// intersection (vertices inside the other triangle, edge-plane crossings,
/// coplanar edge-edge crossings), computed in floating point (so within
/// rounding of the true set). Empty when triangles_intersect() is false.
std::vector<Eigen::Vector3d> triangle_intersection_points(
    const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
    const Eigen::Vector3d& b0, const Eigen::Vector3d& b1, const Eigen::Vector3d& b2);

}  // namespace icd::collision
