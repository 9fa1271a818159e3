// Stable step against near-regular tets (issue 30, item 5): the report's
// steps against the FEM module's dense generalized eigensolve (independent of
// Lanczos), the ideal block's geometry against its closed form, and the
// ratio on near-regular meshes (~1) and on a mesh with one sliver.
#include <icd/mesh/pipeline/fem_step.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <Eigen/Eigenvalues>

#include <icd/fem/stable_step.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/pipeline/tet_quality.hpp>

#include "sliver_block.hpp"

namespace icd::mesh {
namespace {

// Dense oracle: sqrt(lambda_max) of K u = lambda M u (lumped M, all dofs free).
double dense_omega(const TetMesh& m, const fem::Material& mat) {
  fem::Model model(m.V, m.T, mat);
  const Eigen::MatrixXd K = Eigen::MatrixXd(model.elastic().stiffness(m.V));
  Eigen::VectorXd minv_sqrt(K.rows());
  for (Eigen::Index i = 0; i < K.rows(); ++i)
    minv_sqrt[i] = 1.0 / std::sqrt(model.mass()[i / 3]);
  const Eigen::MatrixXd A = minv_sqrt.asDiagonal() * K * minv_sqrt.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A, Eigen::EigenvaluesOnly);
  return std::sqrt(es.eigenvalues().maxCoeff());
}

TEST(FemStep, BccBlockIsTheClosedFormLattice) {
  for (int n : {2, 3, 4}) {
    const double h = 0.37;
    const TetMesh m = bcc_block(n, h);
    ASSERT_EQ(m.T.rows(), 12 * n * n * n - 12 * n * n);
    const Eigen::VectorXd vol = signed_tet_volumes(m.V, m.T);
    EXPECT_NEAR(vol.minCoeff(), h * h * h / 12, 1e-12);
    EXPECT_NEAR(vol.maxCoeff(), h * h * h / 12, 1e-12);
    const TetQuality q = tet_quality(m);
    EXPECT_NEAR(q.min_dihedral_deg, 60.0, 1e-9);  // Sommerville's tet: 60 and 90 deg
    EXPECT_NEAR(q.max_dihedral_deg, 90.0, 1e-9);
    // Every node used; the boundary a closed surface (Euler characteristic 2).
    std::set<int> used(m.T.data(), m.T.data() + m.T.size());
    EXPECT_EQ(static_cast<Eigen::Index>(used.size()), m.V.rows());
    std::set<std::pair<int, int>> edges;
    for (int f = 0; f < m.F.rows(); ++f)
      for (int k = 0; k < 3; ++k)
        edges.insert(std::minmax(m.F(f, k), m.F(f, (k + 1) % 3)));
    std::set<int> surf(m.F.data(), m.F.data() + m.F.size());
    EXPECT_EQ(static_cast<long>(surf.size()) - static_cast<long>(edges.size()) + m.F.rows(), 2);
  }
  EXPECT_THROW(bcc_block(1, 1.0), ParameterError);
  EXPECT_THROW(bcc_block(3, 0.0), ParameterError);
}

TEST(FemStep, StepsAreTheDenseEigenvalueLimitsAndScaleFree) {
  // RK4 undamped: h = 2 sqrt(2) / omega_max (fem/stable_step.hpp), omega_max
  // from the dense eigensolve; the Lanczos bound may exceed it by its residual.
  const TetMesh m = bcc_block(3, 0.1);
  StableStepOptions o;
  o.ideal_cells = 3;
  const StableStepReport r = stable_step_report(m, o);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_TRUE(r.converged);
  const double omega = dense_omega(m, o.material);
  EXPECT_NEAR(r.omega_max, omega, 1e-4 * omega);
  EXPECT_NEAR(r.step, 2 * std::sqrt(2.0) / omega, 1e-4 * r.step);
  // The mesh is the ideal block itself: ratio 1.
  EXPECT_NEAR(r.ratio, 1.0, 1e-6);
  // Scaled by 1000 and rotated: the same ratio; the steps scale with the size.
  TetMesh big = m;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  big.V = (1000.0 * m.V * R.transpose()).eval();
  const StableStepReport rb = stable_step_report(big, o);
  EXPECT_NEAR(rb.ratio, r.ratio, 1e-6);
  EXPECT_NEAR(rb.step, 1000.0 * r.step, 1e-4 * rb.step);
  // Rayleigh damping and symplectic Euler: fem::stable_step_limit of the same omega.
  StableStepOptions d = o;
  d.damping.alpha = 50;
  d.integrator = fem::Integrator::SymplecticEuler;
  const StableStepReport rd = stable_step_report(m, d);
  EXPECT_NEAR(rd.step,
              fem::stable_step_limit(fem::Integrator::SymplecticEuler, rd.omega_max, d.damping),
              1e-12);
  EXPECT_NEAR(rd.omega_max, omega, 1e-4 * omega);
}

TEST(FemStep, NearRegularMeshesGiveRatioNearOne) {
  // Blocks of other sizes than the ideal's, their nodes moved at random by up
  // to 5 % of the lattice edge: the ratio stays near 1.
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n : {4, 6}) {
    TetMesh m = bcc_block(n, 0.05);
    for (Eigen::Index i = 0; i < m.V.rows(); ++i)
      for (int c = 0; c < 3; ++c) m.V(i, c) += 0.05 * 0.05 * u(gen);
    const StableStepReport r = stable_step_report(m);
    ASSERT_TRUE(r.error.empty());
    EXPECT_GT(r.ratio, 0.85) << "n = " << n;
    EXPECT_LT(r.ratio, 1.1) << "n = " << n;
    EXPECT_TRUE(fem_quality_warnings(r, tet_quality(m).min_dihedral_deg).empty());
  }
}

TEST(FemStep, OneSliverSetsTheRatio) {
  // Take the block and move one interior lattice node 92 % of the way to the
  // plane of the opposite face of one of its tets: that tet becomes a flat
  // sliver (its neighbours stay positive). Reference: the dense eigensolve of
  // the same mesh against that of the ideal block (independent of Lanczos).
  TetMesh unchanged = bcc_block(4, 1.0);
  const StableStepReport before = stable_step_report(unchanged);
  TetMesh m;
  ASSERT_TRUE(test::bcc_block_with_centre_sliver(m));
  const TetQuality q = tet_quality(m);
  const StableStepReport r = stable_step_report(m);
  ASSERT_TRUE(r.error.empty());
  const fem::Material mat;
  const TetMesh ideal = bcc_block(5, std::cbrt(12.0 * r.mean_volume));
  const double expected = dense_omega(ideal, mat) / dense_omega(m, mat);  // undamped: 1/omega
  EXPECT_NEAR(r.ratio, expected, 1e-3 * expected);
  // A flat sliver costs less than its angle suggests: its stiffness across
  // the flat direction grows as 1/height but its nodes keep the mass of their
  // other tets (measured 1.00 -> 0.72 here). Small tets cost more (below).
  EXPECT_GT(before.ratio, 0.98);
  EXPECT_LT(r.ratio, 0.8);
  const std::string w = fem_quality_warnings(r, q.min_dihedral_deg);
  EXPECT_EQ(w.find("stable step"), std::string::npos) << w;
  EXPECT_NE(w.find("dihedral angle is"), std::string::npos) << w;
}

TEST(FemStep, OneSmallTetSetsTheRatio) {
  // Shrinking one corner of the block pulls a node towards its neighbour: the
  // tets between them get a short edge and little mass. Undamped RK4 steps
  // are 2 sqrt(2) / omega: the ratio is the ideal block's dense omega over
  // the mesh's, and below the target it warns.
  TetMesh m = bcc_block(3, 1.0);
  // The lattice node (1, 1, 1) and the cell centre (1.5, 1.5, 1.5).
  Eigen::Index a = -1, b = -1;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    if ((m.V.row(i) - Eigen::RowVector3d(1, 1, 1)).norm() < 1e-12) a = i;
    if ((m.V.row(i) - Eigen::RowVector3d(1.5, 1.5, 1.5)).norm() < 1e-12) b = i;
  }
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  m.V.row(a) = m.V.row(b) + 0.03 * (m.V.row(a) - m.V.row(b));  // edge 0.87 -> 0.026
  const TetQuality q = tet_quality(m);
  ASSERT_GT(q.min_volume, 0.0);
  const StableStepReport r = stable_step_report(m);
  const TetMesh ideal = bcc_block(5, std::cbrt(12.0 * r.mean_volume));
  const double expected = dense_omega(ideal, fem::Material{}) / dense_omega(m, fem::Material{});
  EXPECT_NEAR(r.ratio, expected, 1e-3 * expected);
  EXPECT_LT(r.ratio, kStableStepRatioTarget);
  const std::string w = fem_quality_warnings(r, q.min_dihedral_deg);
  EXPECT_NE(w.find("stable step is"), std::string::npos) << w;
}

TEST(FemStep, DegenerateMeshIsReportedNotThrown) {
  TetMesh m = bcc_block(2, 1.0);
  m.V.row(m.T(0, 0)) = m.V.row(m.T(0, 1));  // a zero-volume tet
  const StableStepReport r = stable_step_report(m);
  EXPECT_FALSE(r.error.empty());
  EXPECT_EQ(r.ratio, 0.0);
  fem::Material bad;
  bad.young = -1;
  StableStepOptions o;
  o.material = bad;
  EXPECT_THROW(stable_step_report(bcc_block(2, 1.0), o), ParameterError);
}

}  // namespace
}  // namespace icd::mesh
