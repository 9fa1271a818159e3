#include <icd/fem/tet_mesh_data.hpp>

#include <gtest/gtest.h>

#include "fem_test_utils.hpp"
#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

TEST(TetMeshData, VolumesSumToBoxVolumeAndGradientsReproduceAffineFields) {
  const TetMeshData d = test::box_data(3, 2, 2, {0.6, 0.2, 0.3});
  EXPECT_NEAR(d.rest_volume.sum(), 0.6 * 0.2 * 0.3, 1e-15);
  // Shape functions reproduce a linear field u(X) = A X + b: sum_a u(X_a) grad N_a^T = A.
  Eigen::Matrix3d A;
  A << 1, 2, 3, -4, 5, 6, 7, -8, 9;
  const Eigen::Vector3d b(0.1, -0.2, 0.3);
  for (int e = 0; e < d.num_tets(); ++e) {
    const auto G = d.shape_gradients(e);
    Eigen::Matrix3d grad = Eigen::Matrix3d::Zero();
    for (int a = 0; a < 4; ++a)
      grad += (A * d.rest_positions.row(d.tets(e, a)).transpose() + b) * G.row(a);
    EXPECT_LT((grad - A).norm(), 1e-12 * A.norm()) << "element " << e;
    EXPECT_LT(G.colwise().sum().norm(), 1e-12);
  }
}

TEST(TetMeshData, RejectsInvertedDegenerateAndOutOfRangeTets) {
  TetMesh m = make_unit_tet();
  MatX4i T = m.T;
  std::swap(T(0, 1), T(0, 2));
  EXPECT_THROW(make_tet_mesh_data(m.V, T), InputError);
  MatX3d V = m.V;
  V.row(3) = Eigen::RowVector3d(0.5, 0.5, 0.0);  // flat
  EXPECT_THROW(make_tet_mesh_data(V, m.T), InputError);
  T = m.T;
  T(0, 3) = 4;
  try {
    make_tet_mesh_data(m.V, T);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tet 0"), std::string::npos) << e.what();
  }
  V = m.V;
  V(2, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(make_tet_mesh_data(V, m.T), InputError);
}

}  // namespace
}  // namespace icd::fem
