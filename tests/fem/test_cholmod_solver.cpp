#include <icd/fem/cholmod_solver.hpp>

#include <random>

#include <gtest/gtest.h>
#include <Eigen/SparseCholesky>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

// 1D Laplacian plus a diagonal shift: SPD, with a known residual oracle.
Eigen::SparseMatrix<double> laplacian(int n, double shift) {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2.0 + shift);
    if (i + 1 < n) {
      t.emplace_back(i, i + 1, -1.0);
      t.emplace_back(i + 1, i, -1.0);
    }
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

TEST(CholmodSolver, AnalyseOnceFactorAndSolveManyForEveryOrdering) {
  for (CholmodOrdering ordering :
       {CholmodOrdering::Default, CholmodOrdering::Amd, CholmodOrdering::Metis}) {
    CholmodSolver solver(ordering);
    std::mt19937 gen(0);
    std::uniform_real_distribution<double> u(-1, 1);
    for (double shift : {0.0, 0.5, 3.0}) {
      const Eigen::SparseMatrix<double> A = laplacian(200, shift);
      Eigen::VectorXd b(200);
      for (auto& v : b) v = u(gen);
      ASSERT_TRUE(solver.factorize(A));
      const Eigen::VectorXd x = solver.solve(b);
      EXPECT_LT((A * x - b).norm(), 1e-10 * b.norm());
    }
  }
}

TEST(CholmodSolver, ReportsIndefiniteMatrixAndRefusesToSolveWithoutFactor) {
  CholmodSolver solver;
  EXPECT_THROW(solver.solve(Eigen::VectorXd::Ones(10)), NumericalError);
  const Eigen::SparseMatrix<double> A = laplacian(10, -3.0);  // eigenvalues 2 - 2cos - 3 < 0
  EXPECT_FALSE(solver.factorize(A));
  EXPECT_THROW(solver.solve(Eigen::VectorXd::Ones(10)), NumericalError);
  EXPECT_TRUE(solver.factorize(laplacian(10, 0.1)));
  EXPECT_THROW(solver.solve(Eigen::VectorXd::Ones(9)), ParameterError);
  Eigen::SparseMatrix<double> rect(3, 4);
  rect.makeCompressed();
  EXPECT_THROW(solver.analyze(rect), ParameterError);
}

}  // namespace
}  // namespace icd::fem
