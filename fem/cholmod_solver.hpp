#pragma once
/// A small RAII wrapper around CHOLMOD's supernodal Cholesky factorisation:
/// analyse a sparsity pattern once, then factorise and solve many times.
/// Every CHOLMOD call's status is checked.
#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace icd::fem {

/// Fill-reducing ordering of the symbolic analysis.
enum class CholmodOrdering {
  Default,  ///< CHOLMOD's strategy: AMD, METIS tried when AMD's fill is poor
  Amd,
  Metis  ///< METIS nested dissection (least fill on 3D meshes)
};

/// Sparse symmetric positive definite solver. The matrix is given with both
/// triangles (or at least the upper one); only the upper triangle is read.
/// Constructing one sets OpenBLAS (if that is the BLAS in use) to one thread.
class CholmodSolver {
 public:
  explicit CholmodSolver(CholmodOrdering ordering = CholmodOrdering::Default);
  ~CholmodSolver();
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  /// Symbolic analysis of A's pattern (square, compressed, column-major).
  /// Throws ParameterError for a non-square matrix, NumericalError on a CHOLMOD failure.
  void analyze(const Eigen::SparseMatrix<double>& A);
  /// Numeric factorisation of A (same pattern as analysed; analyses first if needed).
  /// Returns false when A is not positive definite (the factor is then unusable);
  /// throws NumericalError on any other CHOLMOD failure.
  bool factorize(const Eigen::SparseMatrix<double>& A);
  /// Solves A x = b with the last successful factorisation. Throws
  /// NumericalError if there is none, on a CHOLMOD failure or a non-finite result.
  Eigen::VectorXd solve(const Eigen::VectorXd& b);

  bool analyzed() const { return m_factor != nullptr; }
  /// Whether the last factorize() succeeded.
  bool factorized() const { return m_factorized; }

 private:
  struct Impl;
  Impl* m_impl = nullptr;
  void* m_factor = nullptr;  // cholmod_factor*
  long m_rows = -1, m_nnz = -1;
  bool m_factorized = false;
};

}  // namespace icd::fem
