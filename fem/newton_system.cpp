#include <icd/fem/newton_system.hpp>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {

double solve_with_shift(CholmodSolver& solver, const Eigen::SparseMatrix<double>& A,
                        Eigen::SparseMatrix<double>& shifted, const Eigen::VectorXd& b,
                        Eigen::VectorXd& dx) {
  if (solver.factorize(A)) {
    dx = solver.solve(b);
    return 0.0;
  }
  const double dmax = A.diagonal().cwiseAbs().maxCoeff();
  for (double s = 1e-6; s <= 1.0; s *= 100) {
    shifted = A;
    for (int j = 0; j < shifted.outerSize(); ++j) shifted.coeffRef(j, j) += s * dmax;
    if (solver.factorize(shifted)) {
      dx = solver.solve(b);
      return s * dmax;
    }
  }
  throw NumericalError(
      "fem Newton solver: tangent matrix is not positive definite even with a diagonal shift of " +
      std::to_string(dmax) + " (the largest diagonal entry)");
}

}  // namespace icd::fem
