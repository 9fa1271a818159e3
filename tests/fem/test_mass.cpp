#include <icd/fem/mass.hpp>

#include <gtest/gtest.h>

#include "fem_test_utils.hpp"
#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

TEST(Mass, LumpedAndConsistentMassGiveTheRigidBodyMassAndInertia) {
  const Eigen::Vector3d size(0.5, 0.2, 0.3);
  const TetMeshData d = test::box_data(3, 2, 2, size);
  const double rho = 700;
  const double total = rho * size.prod();
  const Eigen::VectorXd m = lumped_mass(d, rho);
  EXPECT_NEAR(m.sum(), total, 1e-12 * total);
  EXPECT_TRUE((m.array() > 0).all());
  const Eigen::SparseMatrix<double> M = consistent_mass_matrix(d, rho);
  // Translation: u = e_x everywhere gives u^T M u = total mass.
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * d.num_nodes);
  for (int i = 0; i < d.num_nodes; ++i) u[3 * i] = 1.0;
  EXPECT_NEAR(u.dot(M * u), total, 1e-12 * total);
  // Linear field u_x = y: u^T M u = rho * integral of y^2 = rho * a*c * b^3/3 (exact for the
  // consistent mass, since y is in the element space).
  for (int i = 0; i < d.num_nodes; ++i) u[3 * i] = d.rest_positions(i, 1);
  const double exact = rho * size.x() * size.z() * std::pow(size.y(), 3) / 3.0;
  EXPECT_NEAR(u.dot(M * u), exact, 1e-12 * exact);
  // Row sums of the consistent mass are the lumped masses.
  const Eigen::VectorXd rows = M * Eigen::VectorXd::Ones(3 * d.num_nodes);
  for (int i = 0; i < d.num_nodes; ++i) EXPECT_NEAR(rows[3 * i + 2], m[i], 1e-12 * m[i]);
  EXPECT_THROW(lumped_mass(d, 0.0), ParameterError);
  EXPECT_THROW(consistent_mass_matrix(d, -1.0), ParameterError);
}

}  // namespace
}  // namespace icd::fem
