#pragma once
/// Backward Euler with Newton iterations solved by CHOLMOD: the implicit
/// reference integrator and the fallback for stiff materials.
#include <icd/fem/cholmod_solver.hpp>
#include <icd/fem/integrators.hpp>

namespace icd::fem {

/// Newton iteration controls.
struct NewtonOptions {
  int max_iterations = 30;  ///< >= 1
  /// Converged when |residual| <= tolerance * reference (see each solver).
  double tolerance = 1e-9;
};

/// What a Newton solve did.
struct NewtonReport {
  bool converged = false;
  int iterations = 0;
  double residual = 0;   ///< final residual norm (free dofs)
  double reference = 0;  ///< the scale the tolerance was relative to
  double max_shift = 0;  ///< largest diagonal shift needed for positive definiteness
};

/// Backward Euler: find v1 with M (v1 - v0) = h f(x0 + h v1, v1), x1 = x0 + h v1.
/// Newton matrix M (1 + h alpha) + (h^2 + h beta) K(x1) + h D(x1) with D the
/// strain-rate damping matrix (the dK/dx v1 term of stiffness damping and the
/// dD/dx v1 term are neglected). The CHOLMOD symbolic analysis is done once.
class BackwardEulerStepper {
 public:
  /// One step of size h (s). The reference scale of the residual is
  /// |M v0| + h (|f_int(x0)| + |f_ext + M g|); when no backtracking step
  /// reduces the residual (round-off floor), it is accepted if within
  /// sqrt(tolerance) of the reference. On non-convergence the state is still
  /// updated with the last iterate and the report says so.
  NewtonReport step(Model& model, State& s, double h, const NewtonOptions& options = {});

 private:
  CholmodSolver m_solver;
  Eigen::SparseMatrix<double> m_A, m_shifted;
};

}  // namespace icd::fem
