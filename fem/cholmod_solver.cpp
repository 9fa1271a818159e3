#include <icd/fem/cholmod_solver.hpp>

#include <cholmod.h>
#include <dlfcn.h>

#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {

struct CholmodSolver::Impl {
  cholmod_common common;
};

namespace {

// A non-owning CHOLMOD view of an Eigen compressed column-major matrix
// (stype = 1: only the upper triangle is used).
cholmod_sparse view(const Eigen::SparseMatrix<double>& A) {
  cholmod_sparse s{};
  s.nrow = static_cast<size_t>(A.rows());
  s.ncol = static_cast<size_t>(A.cols());
  s.nzmax = static_cast<size_t>(A.nonZeros());
  s.p = const_cast<int*>(A.outerIndexPtr());
  s.i = const_cast<int*>(A.innerIndexPtr());
  s.x = const_cast<double*>(A.valuePtr());
  s.stype = 1;
  s.itype = CHOLMOD_INT;
  s.xtype = CHOLMOD_REAL;
  s.dtype = CHOLMOD_DOUBLE;
  s.sorted = 1;
  s.packed = 1;
  return s;
}

void check_status(const cholmod_common& c, const char* call) {
  if (c.status < 0)
    throw NumericalError(std::string("fem::CholmodSolver: ") + call +
                         " failed with CHOLMOD status " + std::to_string(c.status));
}

}  // namespace

CholmodSolver::CholmodSolver(CholmodOrdering ordering) : m_impl(new Impl) {
  // The supernodes of these FEM systems are small: threaded BLAS only spins
  // (measured: 3x the wall time, most of it in sched_yield, on 2 shared cores).
  // OpenBLAS is CHOLMOD's BLAS on Debian; looked up at run time, absent elsewhere.
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
    set(1);
  cholmod_start(&m_impl->common);
  if (ordering != CholmodOrdering::Default) {
    m_impl->common.nmethods = 1;
    m_impl->common.method[0].ordering =
        ordering == CholmodOrdering::Amd ? CHOLMOD_AMD : CHOLMOD_METIS;
    m_impl->common.postorder = 1;
  }
  m_impl->common.print = 0;
  m_impl->common.error_handler = nullptr;
  m_impl->common.quick_return_if_not_posdef = 1;
}

CholmodSolver::~CholmodSolver() {
  if (m_factor) {
    auto* L = static_cast<cholmod_factor*>(m_factor);
    cholmod_free_factor(&L, &m_impl->common);
  }
  cholmod_finish(&m_impl->common);
  delete m_impl;
}

void CholmodSolver::analyze(const Eigen::SparseMatrix<double>& A) {
  if (A.rows() != A.cols() || A.rows() == 0)
    throw ParameterError("fem::CholmodSolver::analyze: matrix is " + std::to_string(A.rows()) +
                         " x " + std::to_string(A.cols()) + ", expected square and non-empty");
  if (!A.isCompressed())
    throw ParameterError("fem::CholmodSolver::analyze: matrix is not compressed");
  if (m_factor) {
    auto* L = static_cast<cholmod_factor*>(m_factor);
    cholmod_free_factor(&L, &m_impl->common);
    m_factor = nullptr;
  }
  cholmod_sparse s = view(A);
  cholmod_factor* L = cholmod_analyze(&s, &m_impl->common);
  check_status(m_impl->common, "cholmod_analyze");
  if (!L) throw NumericalError("fem::CholmodSolver: cholmod_analyze returned no factor");
  m_factor = L;
  m_rows = A.rows();
  m_nnz = A.nonZeros();
  m_factorized = false;
}

bool CholmodSolver::factorize(const Eigen::SparseMatrix<double>& A) {
  if (!m_factor || A.rows() != m_rows || A.nonZeros() != m_nnz) analyze(A);
  cholmod_sparse s = view(A);
  auto* L = static_cast<cholmod_factor*>(m_factor);
  cholmod_factorize(&s, L, &m_impl->common);
  if (m_impl->common.status == CHOLMOD_NOT_POSDEF) {
    m_factorized = false;
    return false;
  }
  check_status(m_impl->common, "cholmod_factorize");
  m_factorized = L->minor == L->n;
  return m_factorized;
}

Eigen::VectorXd CholmodSolver::solve(const Eigen::VectorXd& b) {
  if (!m_factorized) throw NumericalError("fem::CholmodSolver::solve: no successful factorisation");
  if (b.size() != m_rows)
    throw ParameterError("fem::CholmodSolver::solve: right-hand side has " +
                         std::to_string(b.size()) + " entries, expected " + std::to_string(m_rows));
  cholmod_dense d{};
  d.nrow = static_cast<size_t>(b.size());
  d.ncol = 1;
  d.nzmax = d.nrow;
  d.d = d.nrow;
  d.x = const_cast<double*>(b.data());
  d.xtype = CHOLMOD_REAL;
  d.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x =
      cholmod_solve(CHOLMOD_A, static_cast<cholmod_factor*>(m_factor), &d, &m_impl->common);
  check_status(m_impl->common, "cholmod_solve");
  if (!x) throw NumericalError("fem::CholmodSolver: cholmod_solve returned no solution");
  Eigen::VectorXd out = Eigen::Map<const Eigen::VectorXd>(static_cast<double*>(x->x), b.size());
  cholmod_free_dense(&x, &m_impl->common);
  if (!out.allFinite()) throw NumericalError("fem::CholmodSolver::solve: solution is not finite");
  return out;
}

}  // namespace icd::fem
