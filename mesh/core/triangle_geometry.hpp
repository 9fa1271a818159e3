#pragma once
/// Point-triangle geometry shared by the preprocessing (sphere-tree distances),
/// the runtime (sphere-to-node association) and the experiments.
#include <Eigen/Core>

namespace icd {

/// Closest point of the triangle (a, b, c) to p (Ericson, Real-Time
/// Collision Detection, sec. 5.1.5: Voronoi regions of the vertices, edges
/// and face). Degenerate triangles are handled (the result lies on them).
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace icd
