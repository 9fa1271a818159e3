#pragma once
/// Rotation part of a 3x3 deformation gradient (polar decomposition F = R S)
/// by a warm-started Newton iteration with a bounded iteration count.
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

namespace icd::fem {

/// Axial vector a of the skew part of M: (M - M^T)/2 = [a]_x.
inline Eigen::Vector3d skew_axial(const Eigen::Matrix3d& M) {
  return 0.5 * Eigen::Vector3d(M(2, 1) - M(1, 2), M(0, 2) - M(2, 0), M(1, 0) - M(0, 1));
}

/// Updates the unit quaternion q (in/out, warm start) so that R = q.toRotationMatrix()
/// is the proper rotation maximising tr(R^T F): the polar rotation of F when
/// det F > 0, and a well-defined proper rotation for inverted or flat F.
/// Each iteration solves (tr(S) I - S) w = 2 axial(skew(R^T F)), S = sym(R^T F)
/// (Newton on the symmetry condition; quadratic convergence), falling back
/// to the scalar step w = 2 axial / |tr S| (Mueller et al. 2016) where that
/// matrix is not positive definite. Stops when |w| <= tolerance (rad) or after
/// max_iterations: the exit is predictable. Returns the iterations used.
inline int polar_rotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q, int max_iterations = 20,
                          double tolerance = 1e-12) {
  int it = 0;
  for (; it < max_iterations; ++it) {
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Matrix3d A = R.transpose() * F;
    const Eigen::Vector3d a = 2.0 * skew_axial(A);
    const Eigen::Matrix3d S = 0.5 * (A + A.transpose());
    const double tr = S.trace();
    Eigen::Matrix3d N = -S;
    N.diagonal().array() += tr;
    // Sylvester's criterion for N = tr(S) I - S positive definite.
    const double m1 = N(0, 0), m2 = N(0, 0) * N(1, 1) - N(0, 1) * N(1, 0), m3 = N.determinant();
    const double scale = std::abs(tr) + 1e-300;
    Eigen::Vector3d w;
    if (m1 > 1e-8 * scale && m2 > 1e-8 * scale * scale && m3 > 1e-8 * scale * scale * scale)
      w = N.inverse() * a;
    else
      w = a / (scale + 1e-9);
    const double angle = w.norm();
    if (!(angle > tolerance)) break;  // also exits on NaN
    // q <- q * exp(w/2): the normalised first-order quaternion, no trigonometry.
    const Eigen::Quaterniond dq(1.0, 0.5 * w.x(), 0.5 * w.y(), 0.5 * w.z());
    q = (q * dq).normalized();
  }
  return it;
}

}  // namespace icd::fem
