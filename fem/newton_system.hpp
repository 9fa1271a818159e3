#pragma once
/// Shared pieces of the Newton solvers: flattening #V x 3 arrays to 3#V
/// vectors and a CHOLMOD solve with a bounded diagonal shift when the tangent
/// is not positive definite (compressed StVK, buckling).
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <icd/fem/cholmod_solver.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::fem {

/// View of a row-major #V x 3 array as a 3#V vector (dof 3i+c).
inline Eigen::Map<Eigen::VectorXd> flat(MatX3d& m) { return {m.data(), m.size()}; }
inline Eigen::Map<const Eigen::VectorXd> flat(const MatX3d& m) { return {m.data(), m.size()}; }

/// Solves A dx = b (fixed dofs already made identity rows/columns in A and
/// zero in b). If A is not positive definite, retries with A + s diag(d) for
/// s = 1e-6, 1e-4, ..., 1 relative to max|diag A| (a Levenberg-Marquardt step).
/// `shifted` is scratch with A's pattern. Throws NumericalError when every
/// shift fails. Returns the shift used (0 if none).
double solve_with_shift(CholmodSolver& solver, const Eigen::SparseMatrix<double>& A,
                        Eigen::SparseMatrix<double>& shifted, const Eigen::VectorXd& b,
                        Eigen::VectorXd& dx);

}  // namespace icd::fem
