#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include <icd/coupling/barycentric_embedding.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::coupling {
namespace {

// Points inside and slightly outside a structured box: the embedding must
// reproduce them at rest, and follow any affine map of the coarse nodes
// exactly (linear shape functions are exact for affine fields, inside and,
// by extrapolation, outside).
TEST(BarycentricEmbedding, ExactAtRestAndUnderAffineMaps) {
  BoxMeshOptions o;
  o.size = {1.0, 0.5, 0.25};
  o.nx = 6;
  o.ny = 3;
  o.nz = 2;
  const TetMesh box = make_box_tet_mesh(o);
  std::mt19937 rng(0);
  std::uniform_real_distribution<double> u(-0.05, 1.05);
  MatX3d P(500, 3);
  for (int i = 0; i < P.rows(); ++i) P.row(i) << u(rng) * 1.0, u(rng) * 0.5, u(rng) * 0.25;
  const BarycentricEmbedding emb = build_barycentric_embedding(P, box.V, box.T);
  EXPECT_GT(emb.num_outside, 0);
  EXPECT_LT(emb.num_outside, P.rows());
  // Rows sum to one.
  const Eigen::VectorXd rows = emb.W * Eigen::VectorXd::Ones(box.V.rows());
  EXPECT_LT((rows.array() - 1.0).abs().maxCoeff(), 1e-12);

  MatX3d out(P.rows(), 3);
  apply(emb, box.V, out);
  EXPECT_LT((out - P).cwiseAbs().maxCoeff(), 1e-12);

  Eigen::Matrix3d A;
  A << 1.2, 0.3, -0.1, 0.05, 0.8, 0.2, -0.3, 0.1, 1.5;
  const Eigen::RowVector3d b(0.4, -2.0, 3.0);
  const MatX3d Vd = (box.V * A.transpose()).rowwise() + b;
  const MatX3d Pd = (P * A.transpose()).rowwise() + b;
  apply(emb, Vd, out);
  EXPECT_LT((out - Pd).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(BarycentricEmbedding, InsidePointsUseAContainingTet) {
  const TetMesh tet = make_unit_tet();
  MatX3d P(2, 3);
  P << 0.1, 0.2, 0.3, 2.0, 2.0, 2.0;
  const BarycentricEmbedding emb = build_barycentric_embedding(P, tet.V, tet.T);
  EXPECT_EQ(emb.num_outside, 1);
  EXPECT_NEAR(emb.W.coeff(0, 0), 0.4, 1e-15);
  EXPECT_NEAR(emb.W.coeff(0, 3), 0.3, 1e-15);
}

TEST(BarycentricEmbedding, BadInputThrows) {
  const TetMesh tet = make_unit_tet();
  MatX3d P(1, 3);
  P << std::nan(""), 0, 0;
  EXPECT_THROW(build_barycentric_embedding(P, tet.V, tet.T), ParameterError);
  MatX4i T(1, 4);
  T << 0, 1, 2, 9;
  P << 0, 0, 0;
  EXPECT_THROW(build_barycentric_embedding(P, tet.V, T), ParameterError);
}

}  // namespace
}  // namespace icd::coupling
