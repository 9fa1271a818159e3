// Internal forces against independent oracles: finite differences of the
// energy, rigid motions, and the affine patch test.
#include <icd/fem/forces.hpp>

#include <gtest/gtest.h>
#include <Eigen/SVD>

#include <icd/fem/constitutive.hpp>
#include <icd/fem/element_kernels.hpp>
#include <icd/fem/lane_kernels.hpp>
#include "fem_test_utils.hpp"
#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

class ForcesPerModel : public ::testing::TestWithParam<MaterialModel> {};

// A moderately deformed state (|F - I| ~ 0.2) of a 2x1x1-cell box of 0.1 m cells.
MatX3d deformed(const TetMeshData& d, unsigned seed, double amplitude = 0.02) {
  return d.rest_positions + amplitude * test::random_field(d.num_nodes, seed);
}

TEST_P(ForcesPerModel, ForcesAreMinusTheFiniteDifferenceGradientOfTheEnergy) {
  const TetMeshData d = test::box_data(2, 1, 1, {0.2, 0.1, 0.1});
  ElasticForces forces(d, test::material(GetParam()));
  MatX3d x = deformed(d, 1);
  MatX3d f(d.num_nodes, 3);
  const double W = forces.compute_with_energy(x, f);
  EXPECT_NEAR(W, forces.energy(x), 1e-12 * std::abs(W));
  // Central differences: truncation ~ h^2 W''' and round-off ~ eps W / h; with
  // h = 1e-7 m on 0.1 m elements both are ~1e-7 relative to the force scale.
  const double h = 1e-7;
  const double scale = f.norm();
  for (int i = 0; i < d.num_nodes; ++i)
    for (int c = 0; c < 3; ++c) {
      MatX3d xp = x, xm = x;
      xp(i, c) += h;
      xm(i, c) -= h;
      const double fd = -(forces.energy(xp) - forces.energy(xm)) / (2 * h);
      EXPECT_NEAR(f(i, c), fd, 1e-6 * scale) << "node " << i << " axis " << c;
    }
}

TEST_P(ForcesPerModel, StiffnessIsTheFiniteDifferenceJacobianAndDifferentialMatchesIt) {
  const TetMeshData d = test::box_data(2, 1, 1, {0.2, 0.1, 0.1});
  ElasticForces forces(d, test::material(GetParam()));
  const MatX3d x = deformed(d, 2);
  const Eigen::MatrixXd K = Eigen::MatrixXd(forces.stiffness(x));
  const int n = 3 * d.num_nodes;
  EXPECT_LT((K - K.transpose()).norm(), 1e-10 * K.norm());
  const double h = 1e-7;
  MatX3d fp(d.num_nodes, 3), fm(d.num_nodes, 3);
  for (int j = 0; j < n; ++j) {
    MatX3d xp = x, xm = x;
    xp(j / 3, j % 3) += h;
    xm(j / 3, j % 3) -= h;
    forces.compute(xp, fp);
    forces.compute(xm, fm);
    const Eigen::VectorXd col = -(Eigen::Map<const Eigen::VectorXd>(fp.data(), n) -
                                  Eigen::Map<const Eigen::VectorXd>(fm.data(), n)) /
                                (2 * h);
    EXPECT_LT((K.col(j) - col).norm(), 1e-6 * K.norm()) << "dof " << j;
  }
  const MatX3d dx = test::random_field(d.num_nodes, 3);
  MatX3d df(d.num_nodes, 3);
  forces.differential(x, dx, df);
  const Eigen::VectorXd Kdx = K * Eigen::Map<const Eigen::VectorXd>(dx.data(), n);
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(df.data(), n) + Kdx).norm(), 1e-12 * Kdx.norm());
}

TEST_P(ForcesPerModel, RigidMotionGivesZeroForceExceptForLinear) {
  const TetMeshData d = test::box_data(3, 2, 2, {0.3, 0.2, 0.2});
  const Material mat = test::material(GetParam());
  ElasticForces forces(d, mat);
  const Eigen::Matrix3d R = test::some_rotation();
  MatX3d x = (d.rest_positions * R.transpose()).rowwise() + Eigen::RowVector3d(0.3, -1.0, 2.0);
  MatX3d f(d.num_nodes, 3);
  const double W = forces.compute_with_energy(x, f);
  // Force scale of a unit strain: E * (element face area ~ (0.1 m)^2).
  const double unit = mat.young * 0.01;
  if (GetParam() == MaterialModel::Linear) {
    EXPECT_GT(f.cwiseAbs().maxCoeff(), 0.1 * unit);  // linear elasticity is not invariant
  } else {
    EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-12 * unit);
    EXPECT_LT(std::abs(W), 1e-12 * mat.young * 0.012);
  }
}

TEST_P(ForcesPerModel, PatchTestAffineFieldGivesAnalyticStressAndBalancedInteriorNodes) {
  const Eigen::Vector3d size(0.3, 0.3, 0.3);
  const TetMesh mesh = test::box(3, 3, 3, size);
  const TetMeshData d = make_tet_mesh_data(mesh.V, mesh.T);
  const Material mat = test::material(GetParam());
  const Lame l = lame_parameters(mat);
  ElasticForces forces(d, mat);
  Eigen::Matrix3d A;
  A << 1.05, 0.02, -0.03, 0.01, 0.97, 0.04, -0.02, 0.03, 1.02;
  const MatX3d x = (d.rest_positions * A.transpose()).rowwise() + Eigen::RowVector3d(0.1, 0.2, 0.3);
  MatX3d f(d.num_nodes, 3);
  const double W = forces.compute_with_energy(x, f);
  // Analytic first Piola-Kirchhoff stress of the homogeneous deformation F = A,
  // written from the textbook definitions (not the library's laws).
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d P;
  double psi = 0;
  switch (GetParam()) {
    case MaterialModel::Linear: {
      const Eigen::Matrix3d eps = 0.5 * (A + A.transpose()) - I;
      P = 2 * l.mu * eps + l.lambda * eps.trace() * I;
      psi = l.mu * (eps.array() * eps.array()).sum() + 0.5 * l.lambda * eps.trace() * eps.trace();
      break;
    }
    case MaterialModel::StVK: {
      const Eigen::Matrix3d E = 0.5 * (A.transpose() * A - I);
      P = A * (2 * l.mu * E + l.lambda * E.trace() * I);
      psi = l.mu * (E.array() * E.array()).sum() + 0.5 * l.lambda * E.trace() * E.trace();
      break;
    }
    case MaterialModel::Corotational: {
      Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();  // det A > 0
      const Eigen::Matrix3d S = R.transpose() * A;
      P = R * (2 * l.mu * (S - I) + l.lambda * (S - I).trace() * I);
      psi = l.mu * (S - I).squaredNorm() + 0.5 * l.lambda * (S - I).trace() * (S - I).trace();
      break;
    }
    case MaterialModel::StableNeoHookean: {
      const double J = A.determinant(), lp = l.lambda + l.mu;
      const Eigen::Matrix3d dJ = J * A.inverse().transpose();
      P = l.mu * A + (lp * (J - 1) - l.mu) * dJ;
      psi = 0.5 * l.mu * (A.squaredNorm() - 3) - l.mu * (J - 1) + 0.5 * lp * (J - 1) * (J - 1);
      break;
    }
  }
  EXPECT_NEAR(W, psi * size.prod(), 1e-12 * std::abs(psi * size.prod()));
  for (int e = 0; e < d.num_tets(); ++e)
    EXPECT_LT((d.deformation_gradient(x, e) - A).norm(), 1e-13);
  // Nodal forces: interior nodes are balanced; the internal force of a boundary
  // node balances the traction P N of its rest boundary faces (one third of
  // each face area for linear triangles), i.e. equals minus that traction.
  MatX3d expected = MatX3d::Zero(d.num_nodes, 3);
  for (int k = 0; k < mesh.F.rows(); ++k) {
    const Eigen::Vector3d X0 = mesh.V.row(mesh.F(k, 0)), X1 = mesh.V.row(mesh.F(k, 1)),
                          X2 = mesh.V.row(mesh.F(k, 2));
    const Eigen::Vector3d area_normal = 0.5 * (X1 - X0).cross(X2 - X0);
    for (int a = 0; a < 3; ++a) expected.row(mesh.F(k, a)) -= (P * area_normal / 3.0).transpose();
  }
  const double scale = P.norm() * 0.01;  // stress x element face area
  EXPECT_LT((f - expected).cwiseAbs().maxCoeff(), 1e-12 * scale);
  // The interior nodes of the 3x3x3 grid carry no external face.
  for (int k = 1; k <= 2; ++k)
    for (int j = 1; j <= 2; ++j)
      for (int i = 1; i <= 2; ++i) EXPECT_LT(f.row(i + 4 * (j + 4 * k)).norm(), 1e-12 * scale);
}

TEST_P(ForcesPerModel, FastKernelsAgreeWithTheEigenReferencePath) {
  // compute() runs the lane / scalar kernels, compute_with_energy() the Eigen
  // laws of constitutive.hpp: two independent codings of the same formulas.
  // 30 tets: three full 8-element lane blocks and a partial one.
  const TetMeshData d = test::box_data(5, 1, 1, {0.5, 0.1, 0.1});
  ElasticForces forces(d, test::material(GetParam()));
  const MatX3d x = deformed(d, 9);
  MatX3d fast(d.num_nodes, 3), ref(d.num_nodes, 3);
  forces.compute(x, fast);
  forces.compute_with_energy(x, ref);
  EXPECT_LT((fast - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff());
}

TEST_P(ForcesPerModel, FusedHealthMatchesTheSeparatePassForAnyThreadCount) {
  // compute_with_health(): the forces of compute() bitwise, and the health of
  // the separate sequential pass health(): same smallest det F and element,
  // same energy up to summation order; with an inverted element and with a
  // non-finite node. 1,080 tets: several 512-element chunks and lane blocks.
  const TetMeshData d = test::box_data(9, 5, 4, {0.9, 0.5, 0.4});
  for (int threads : {1, 2}) {
    ForceOptions fo;
    fo.num_threads = threads;
    ElasticForces forces(d, test::material(GetParam()), fo);
    MatX3d x = deformed(d, 21, 0.01);
    MatX3d f(d.num_nodes, 3), g(d.num_nodes, 3);
    for (int variant = 0; variant < 3; ++variant) {
      if (variant == 1)
        x.row(d.tets(700, 0)) =
            x.row(d.tets(700, 1)) + (x.row(d.tets(700, 1)) - x.row(d.tets(700, 0)));
      if (variant == 2) x(d.tets(300, 2), 1) = std::numeric_limits<double>::quiet_NaN();
      const ElementHealth h = forces.compute_with_health(x, f);
      forces.compute(x, g);
      const ElementHealth ref = forces.health(x);
      EXPECT_TRUE(f.cwiseEqual(g).all() || variant == 2)
          << "threads " << threads << " variant " << variant;
      if (variant < 2) {
        EXPECT_NEAR(h.energy, ref.energy, 1e-12 * std::abs(ref.energy));
        EXPECT_EQ(h.min_det_f, ref.min_det_f);
        EXPECT_EQ(h.min_det_f_element, ref.min_det_f_element);
        EXPECT_EQ(h.first_nonfinite_element, -1);
      } else {
        EXPECT_GE(h.first_nonfinite_element, 0);
        EXPECT_EQ(h.first_nonfinite_element, ref.first_nonfinite_element);
      }
      if (variant == 1) {
        EXPECT_LE(h.min_det_f, 0.0);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllModels, ForcesPerModel, ::testing::ValuesIn(test::all_models()),
                         test::model_name);

TEST_P(ForcesPerModel, OrientationCheckMatchesABruteForceDeterminantScan) {
  // compute_with_orientation_check(): the forces of compute() bitwise, and
  // true iff every element's det F (Eigen's determinant of the deformation
  // gradient, element by element) is > 0; with an element inverted in the
  // last, partial lane block and in a full one, and with a NaN coordinate.
  // 630 tets: two 512-element chunks, 78 whole 8-lane blocks and a partial one.
  const TetMeshData d = test::box_data(7, 5, 3, {0.7, 0.5, 0.3});
  ASSERT_NE(d.num_tets() % 8, 0);
  for (int threads : {1, 2}) {
    ForceOptions fo;
    fo.num_threads = threads;
    for (int variant = 0; variant < 4; ++variant) {
      // Fresh objects: corotational's warm-start rotations are state.
      ElasticForces forces(d, test::material(GetParam()), fo),
          plain(d, test::material(GetParam()), fo);
      MatX3d x = deformed(d, 23, 0.01);
      auto invert = [&](int e) {
        x.row(d.tets(e, 0)) = x.row(d.tets(e, 1)) + (x.row(d.tets(e, 1)) - x.row(d.tets(e, 0)));
      };
      if (variant == 1) invert(d.num_tets() - 1);
      if (variant == 2) invert(200);
      if (variant == 3) x(d.tets(300, 2), 1) = std::numeric_limits<double>::quiet_NaN();
      bool expected = true;
      for (int e = 0; e < d.num_tets(); ++e)
        expected = expected && d.deformation_gradient(x, e).determinant() > 0;
      MatX3d f(d.num_nodes, 3), g(d.num_nodes, 3);
      const bool oriented = forces.compute_with_orientation_check(x, f);
      plain.compute(x, g);
      EXPECT_EQ(oriented, expected) << "threads " << threads << " variant " << variant;
      EXPECT_EQ(expected, variant == 0) << "variant " << variant;  // the cases are what they claim
      if (variant < 3) {
        EXPECT_TRUE(f.cwiseEqual(g).all()) << "threads " << threads << " variant " << variant;
      }
    }
  }
}

TEST(Forces, LaneKernelsMatchTheScalarKernelsPerElement) {
  // The 8-lane kernels (forces, fused health, force differential) against the
  // scalar per-element kernels of element_kernels.hpp: forces, det F and
  // energy density bitwise (same operation sequence), the differential to
  // round-off. 5 elements in the block (3 padding lanes).
  const TetMeshData d = test::box_data(1, 1, 1, {0.1, 0.1, 0.1});  // 5 or 6 tets
  const int count = std::min(d.num_tets(), 8);
  lanes::Block block{};
  for (int e = 0; e < count; ++e) {
    for (int k = 0; k < 9; ++k) block.dinv[k][e] = d.dm_inv[e].data()[k];
    block.volume[e] = d.rest_volume[e];
  }
  const MatX3d x = deformed(d, 31, 0.03), dx = test::random_field(d.num_nodes, 32);
  const double mu = 3.1e5, lambda = 7.7e5;
  auto check = [&](auto tag, auto stress, auto energy, auto dstress) {
    constexpr MaterialModel kModel = decltype(tag)::value;
    double out[8][12], psi[8], det[8], dout[8][12];
    lanes::block_forces<kModel, lanes::LaneCheck::Full>(x.data(), d.tets.data(), count, block, mu,
                                                        lambda, out, psi, det);
    lanes::block_differential<kModel>(x.data(), dx.data(), d.tets.data(), count, block, mu, lambda,
                                      dout);
    // The orientation check: the same forces and det F, no energy density.
    double out_o[8][12], det_o[8];
    lanes::block_forces<kModel, lanes::LaneCheck::Orientation>(
        x.data(), d.tets.data(), count, block, mu, lambda, out_o, nullptr, det_o);
    for (int e = 0; e < count; ++e) {
      EXPECT_EQ(det_o[e], det[e]) << to_string(kModel) << " element " << e;
      for (int k = 0; k < 12; ++k)
        EXPECT_EQ(out_o[e][k], out[e][k]) << to_string(kModel) << " element " << e;
    }
    for (int e = 0; e < count; ++e) {
      const int* t = d.tets.data() + 4 * e;
      const double* D = d.dm_inv[e].data();
      double F[9], dF[9], P[9], dP[9], H[9], dH[9];
      kernels::deformation_gradient(&x(t[0], 0), &x(t[1], 0), &x(t[2], 0), &x(t[3], 0), D, F);
      kernels::deformation_gradient(&dx(t[0], 0), &dx(t[1], 0), &dx(t[2], 0), &dx(t[3], 0), D, dF);
      stress(F, P);
      dstress(F, dF, dP);
      kernels::nodal_forces(P, D, d.rest_volume[e], H);
      kernels::nodal_forces(dP, D, d.rest_volume[e], dH);
      const double J = kernels::determinant(F);
      EXPECT_EQ(det[e], J) << to_string(kModel) << " element " << e;
      EXPECT_EQ(psi[e], energy(F, J)) << to_string(kModel) << " element " << e;
      double scale = 0;
      for (double h : dH) scale = std::max(scale, std::abs(h));
      for (int r = 0; r < 3; ++r)
        for (int a = 1; a < 4; ++a) {
          EXPECT_EQ(out[e][3 * a + r], H[3 * r + a - 1]) << to_string(kModel) << " element " << e;
          EXPECT_NEAR(dout[e][3 * a + r], dH[3 * r + a - 1], 1e-13 * scale)
              << to_string(kModel) << " element " << e;
        }
    }
  };
  using kernels::determinant;
  check(
      std::integral_constant<MaterialModel, MaterialModel::Linear>{},
      [&](const double* F, double* P) { kernels::linear_stress(F, mu, lambda, P); },
      [&](const double* F, double) { return kernels::linear_energy(F, mu, lambda); },
      [&](const double*, const double* dF, double* dP) {
        kernels::linear_stress_differential(dF, mu, lambda, dP);
      });
  check(
      std::integral_constant<MaterialModel, MaterialModel::StVK>{},
      [&](const double* F, double* P) { kernels::stvk_stress(F, mu, lambda, P); },
      [&](const double* F, double) { return kernels::stvk_energy(F, mu, lambda); },
      [&](const double* F, const double* dF, double* dP) {
        kernels::stvk_stress_differential(F, dF, mu, lambda, dP);
      });
  check(
      std::integral_constant<MaterialModel, MaterialModel::StableNeoHookean>{},
      [&](const double* F, double* P) { kernels::stable_neo_hookean_stress(F, mu, lambda, P); },
      [&](const double* F, double J) {
        return kernels::stable_neo_hookean_energy(F, J, mu, lambda);
      },
      [&](const double* F, const double* dF, double* dP) {
        kernels::stable_neo_hookean_stress_differential(F, dF, mu, lambda, dP);
      });
}

TEST(Forces, RejectsShapeMismatch) {
  const TetMeshData d = test::box_data(1, 1, 1);
  ElasticForces forces(d, test::material(MaterialModel::StVK));
  MatX3d x(d.num_nodes + 1, 3), f(d.num_nodes, 3);
  EXPECT_THROW(forces.compute(x, f), ParameterError);
}

}  // namespace
}  // namespace icd::fem
