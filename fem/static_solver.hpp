#pragma once
/// Static equilibrium by Newton's method with CHOLMOD: reference deformations
/// f_int(x) + f_ext + M g = 0 on the free nodes.
#include <icd/fem/backward_euler.hpp>
#include <icd/fem/cholmod_solver.hpp>
#include <icd/fem/model.hpp>

namespace icd::fem {

/// Static equilibrium solver. Keeps its CHOLMOD analysis between solves of
/// the same model (same pattern).
class StaticSolver {
 public:
  /// Solves for x (in: initial guess, e.g. rest positions; out: equilibrium;
  /// fixed nodes stay where they are). Converged when |residual| <= tolerance
  /// * |f_ext + M g| over the free nodes, when the Newton update is below
  /// 1e-14 of the mesh size, or when no step along the Newton direction
  /// reduces the potential or the residual while |residual| <= sqrt(tolerance)
  /// * |f_ext + M g| (the round-off floor of the internal forces). Line search
  /// on the total potential W(x) - (f_ext + M g) . x. Damping plays no role.
  NewtonReport solve(Model& model, MatX3d& x, const NewtonOptions& options = {100, 1e-10});

 private:
  CholmodSolver m_solver;
  Eigen::SparseMatrix<double> m_A, m_shifted;
};

}  // namespace icd::fem
