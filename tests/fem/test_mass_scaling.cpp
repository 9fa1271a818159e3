// Selective mass scaling: against dense eigensolves of the same model with
// and without the added mass (independent of the Lanczos estimates the
// scaling and the Simulator use). The mesh: a near-regular BCC block with
// two thin tets glued on its surface, whose apex nodes are light and stiff
// (the light surface nodes of a thin part of a Mesh_3 mesh).
#include <icd/fem/mass_scaling.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

#include <icd/fem/model.hpp>
#include <icd/fem/simulator.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::fem {
namespace {

struct Mesh {
  MatX3d V;
  MatX4i T;
};

// A 3-cell BCC block of edge 1 and, on two of its boundary faces, a tet whose
// apex sits `heights` above the face centroid (outside the block).
Mesh block_with_light_nodes(const std::vector<double>& heights) {
  Mesh m;
  bcc_block(3, 1.0, m.V, m.T);
  const MatX3i F = boundary_faces(m.T);
  const Eigen::RowVector3d centre = m.V.colwise().mean();
  std::vector<Eigen::Index> faces{0, F.rows() / 2};  // two far-apart boundary faces
  for (size_t k = 0; k < heights.size(); ++k) {
    const Eigen::Index f = faces[k];
    const Eigen::Vector3d a = m.V.row(F(f, 0)), b = m.V.row(F(f, 1)), c = m.V.row(F(f, 2));
    Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    const Eigen::Vector3d g = (a + b + c) / 3;
    if (n.dot(g - centre.transpose()) < 0) n = -n;  // outward
    const Eigen::Index apex = m.V.rows();
    m.V.conservativeResize(apex + 1, 3);
    m.V.row(apex) = (g + heights[k] * n).transpose();
    m.T.conservativeResize(m.T.rows() + 1, 4);
    Eigen::RowVector4i t(F(f, 0), F(f, 1), F(f, 2), static_cast<int>(apex));
    const Eigen::Vector3d d = m.V.row(apex);
    if ((b - a).dot((c - a).cross(d - a)) < 0) std::swap(t[1], t[2]);
    m.T.row(m.T.rows() - 1) = t;
  }
  return m;
}

Eigen::MatrixXd dense_stiffness(Model& model, const MatX3d& V) {
  return Eigen::MatrixXd(model.elastic().stiffness(V));
}

// All eigenvalues (ascending) of K u = lambda M u, lumped M = diag(mass).
Eigen::VectorXd dense_eigenvalues(const Eigen::MatrixXd& K, const Eigen::VectorXd& mass) {
  Eigen::VectorXd s(K.rows());
  for (Eigen::Index i = 0; i < K.rows(); ++i) s[i] = 1.0 / std::sqrt(mass[i / 3]);
  const Eigen::MatrixXd A = s.asDiagonal() * K * s.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues();
}

double dense_ideal_omega(const Material& mat, double mean_volume) {
  Mesh b;
  bcc_block(5, std::cbrt(12.0 * mean_volume), b.V, b.T);
  Model model(b.V, b.T, mat);
  return std::sqrt(dense_eigenvalues(dense_stiffness(model, b.V), model.mass()).maxCoeff());
}

TEST(MassScaling, IdealIsTheDenseTopFrequencyOfTheBccBlockForAnyScale) {
  Material mat;
  mat.model = MaterialModel::StableNeoHookean;
  mat.poisson = 0.3;
  for (double volume : {1e-6, 0.02}) {
    mat.young = volume < 1e-3 ? 3e5 : 2e7;
    EXPECT_NEAR(ideal_max_frequency(mat, volume), dense_ideal_omega(mat, volume),
                1e-4 * dense_ideal_omega(mat, volume));
  }
  EXPECT_THROW(ideal_max_frequency(mat, 0.0), ParameterError);
}

TEST(MassScaling, ReachesTheTargetAddingMassOnlyToTheLightNodes) {
  const Mesh m = block_with_light_nodes({0.03, 0.08});
  const Material mat;
  Model plain(m.V, m.T, mat);
  const Eigen::MatrixXd K = dense_stiffness(plain, m.V);
  const Eigen::VectorXd m0 = plain.mass();
  const double ideal = dense_ideal_omega(mat, plain.mesh().rest_volume.mean());
  const double ratio0 = ideal / std::sqrt(dense_eigenvalues(K, m0).maxCoeff());
  ASSERT_LT(ratio0, 0.15);  // the apexes set the step

  for (double target : {0.4, 0.5, 0.6}) {
    SCOPED_TRACE(target);
    ModelOptions mo;
    mo.mass_scaling.target_ratio = target;
    Model scaled(m.V, m.T, mat, mo);
    const MassScalingReport& r = scaled.mass_scaling();
    const Eigen::VectorXd& ms = scaled.mass();
    // The report's estimates against the dense solves.
    EXPECT_NEAR(r.ratio_before, ratio0, 1e-3 * ratio0);
    const double ratio = ideal / std::sqrt(dense_eigenvalues(K, ms).maxCoeff());
    EXPECT_NEAR(r.ratio_after, ratio, 1e-3 * ratio);
    // Reached, and just enough: not more than 5 % past the target.
    EXPECT_TRUE(r.reached);
    EXPECT_GE(ratio, target * (1 - 1e-6));
    EXPECT_LE(ratio, target * 1.05);
    // Per node, from the dense K's diagonal blocks: a node whose own
    // frequency is within the threshold keeps its mass bitwise; the others
    // get exactly the mass that puts them on it.
    int scaled_nodes = 0;
    double added = 0, max_factor = 1;
    for (int i = 0; i < scaled.num_nodes(); ++i) {
      const double lambda = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
                                K.block<3, 3>(3 * i, 3 * i), Eigen::EigenvaluesOnly)
                                .eigenvalues()[2];
      const double own = std::sqrt(lambda / m0[i]);
      if (own <= r.node_omega * (1 - 1e-9)) {
        EXPECT_EQ(ms[i], m0[i]) << "node " << i;
      } else if (own > r.node_omega * (1 + 1e-9)) {
        EXPECT_NEAR(ms[i], lambda / (r.node_omega * r.node_omega), 1e-9 * ms[i]) << "node " << i;
        ++scaled_nodes;
        added += ms[i] - m0[i];
        max_factor = std::max(max_factor, ms[i] / m0[i]);
      }
    }
    EXPECT_EQ(r.scaled_nodes, scaled_nodes);
    EXPECT_NEAR(r.added_mass, added, 1e-9 * m0.sum());
    EXPECT_NEAR(r.added_fraction, added / m0.sum(), 1e-12);
    EXPECT_NEAR(r.max_factor, max_factor, 1e-9 * max_factor);
    // The threshold is not far below the first pass's (ideal / target): the
    // two apexes and their neighbours only, a bounded share of the mass
    // (measured at 0.6: threshold 0.58 x ideal / target, 2.2 % added).
    EXPECT_GT(r.node_omega, 0.5 * ideal / target);
    EXPECT_LE(scaled_nodes, 8);
    EXPECT_LT(r.added_fraction, 0.025);
  }
  // Already above the target: nothing added.
  ModelOptions low;
  low.mass_scaling.target_ratio = 0.5 * ratio0;
  Model untouched(m.V, m.T, mat, low);
  EXPECT_EQ(untouched.mass_scaling().scaled_nodes, 0);
  EXPECT_TRUE((untouched.mass().array() == m0.array()).all());
  // Bad options.
  ModelOptions bad;
  bad.mass_scaling.target_ratio = 1.5;
  EXPECT_THROW(Model(m.V, m.T, mat, bad), ParameterError);
  bad.mass_scaling.target_ratio = 0.5;
  bad.mass_scaling.max_added_fraction = 0;
  EXPECT_THROW(Model(m.V, m.T, mat, bad), ParameterError);
}

TEST(MassScaling, AddedMassLimitStopsTheScaling) {
  const Mesh m = block_with_light_nodes({0.03, 0.08});
  ModelOptions mo;
  mo.mass_scaling.target_ratio = 0.5;
  mo.mass_scaling.max_added_fraction = 1e-3;  // the target needs 1.1 %
  Model model(m.V, m.T, Material{}, mo);
  const MassScalingReport& r = model.mass_scaling();
  EXPECT_FALSE(r.reached);
  EXPECT_LE(r.added_fraction, 1e-3);
  EXPECT_NE(r.to_string().find("not reached"), std::string::npos) << r.to_string();
  EXPECT_TRUE(r.mass_limited);
  EXPECT_FALSE(r.pass_limited);
  EXPECT_NE(r.to_string().find("added-mass limit"), std::string::npos) << r.to_string();
  EXPECT_EQ(r.to_string().find("ran out of passes"), std::string::npos) << r.to_string();
}

TEST(MassScaling, AMassLimitedScalingSpendsItsWholeBudget) {
  // The target 0.6 needs several passes; with an added-mass limit between
  // what the first pass adds and what the target needs, the scaling must end
  // at the limit (the threshold whose added mass is the limit), not at the
  // last pass before a step that would have crossed it.
  const Mesh m = block_with_light_nodes({0.03, 0.08});
  const Material mat;
  ModelOptions mo;
  mo.mass_scaling.target_ratio = 0.6;
  mo.mass_scaling.max_passes = 1;
  const double first = Model(m.V, m.T, mat, mo).mass_scaling().added_fraction;
  mo.mass_scaling.max_passes = MassScaling{}.max_passes;
  const MassScalingReport full = Model(m.V, m.T, mat, mo).mass_scaling();
  ASSERT_TRUE(full.reached);
  ASSERT_GT(full.added_fraction, 1.5 * first);
  for (const double share : {0.1, 0.5, 0.9}) {
    mo.mass_scaling.max_added_fraction = first + share * (full.added_fraction - first);
    Model model(m.V, m.T, mat, mo);
    const MassScalingReport& r = model.mass_scaling();
    EXPECT_FALSE(r.reached) << share;
    EXPECT_TRUE(r.mass_limited) << share;
    EXPECT_LE(r.added_fraction, mo.mass_scaling.max_added_fraction * (1 + 1e-9)) << share;
    EXPECT_GE(r.added_fraction, 0.999 * mo.mass_scaling.max_added_fraction) << share;
    const double added = (model.mass().sum() - Model(m.V, m.T, mat).mass().sum()) /
                         Model(m.V, m.T, mat).mass().sum();
    EXPECT_NEAR(added, r.added_fraction, 1e-12) << share;
  }
}

TEST(MassScaling, PassLimitIsNamedAndFurtherPassesReachTheTarget) {
  // At 0.6 the threshold must fall to ~0.58 x its first value (the light
  // nodes' neighbours share the top mode), so one pass cannot reach it: the
  // scaling stops at its pass limit, far below the added-mass limit, and says
  // so (it used to blame the mass); with the default passes it reaches it.
  const Mesh m = block_with_light_nodes({0.03, 0.08});
  const Material mat;
  Model plain(m.V, m.T, mat);
  const Eigen::MatrixXd K = dense_stiffness(plain, m.V);
  const double ideal = dense_ideal_omega(mat, plain.mesh().rest_volume.mean());
  ModelOptions mo;
  mo.mass_scaling.target_ratio = 0.6;
  mo.mass_scaling.max_passes = 1;
  Model one(m.V, m.T, mat, mo);
  const MassScalingReport& r1 = one.mass_scaling();
  EXPECT_EQ(r1.passes, 1);
  EXPECT_FALSE(r1.reached);
  EXPECT_TRUE(r1.pass_limited);
  EXPECT_FALSE(r1.mass_limited);
  EXPECT_LT(r1.added_fraction, 0.5 * mo.mass_scaling.max_added_fraction);
  EXPECT_LT(ideal / std::sqrt(dense_eigenvalues(K, one.mass()).maxCoeff()), 0.6);
  EXPECT_NE(r1.to_string().find("ran out of passes (1, MassScaling::max_passes) below the added-mass limit"), std::string::npos)
      << r1.to_string();
  EXPECT_EQ(r1.to_string().find("would exceed"), std::string::npos) << r1.to_string();
  mo.mass_scaling.max_passes = MassScaling{}.max_passes;
  Model all(m.V, m.T, mat, mo);
  const MassScalingReport& r = all.mass_scaling();
  EXPECT_TRUE(r.reached);
  EXPECT_GT(r.passes, 1);
  EXPECT_FALSE(r.pass_limited || r.mass_limited);
  EXPECT_GE(ideal / std::sqrt(dense_eigenvalues(K, all.mass()).maxCoeff()), 0.6 * (1 - 1e-6));
  EXPECT_EQ(r.to_string().find("not reached"), std::string::npos) << r.to_string();
  mo.mass_scaling.max_passes = 0;
  EXPECT_THROW(Model(m.V, m.T, mat, mo), ParameterError);
}

TEST(MassScaling, TheSimulatorStepsWithTheScaledMassesBelowTheTrueLimit) {
  const Mesh m = block_with_light_nodes({0.03, 0.08});
  for (MaterialModel model : {MaterialModel::StVK, MaterialModel::StableNeoHookean}) {
    Material mat;
    mat.model = model;
    ModelOptions mo;
    mo.mass_scaling.target_ratio = 0.5;
    Model scaled(m.V, m.T, mat, mo);
    const Eigen::MatrixXd K = dense_stiffness(scaled, m.V);
    const double omega = std::sqrt(dense_eigenvalues(K, scaled.mass()).maxCoeff());
    const double omega_plain =
        std::sqrt(dense_eigenvalues(K, Model(m.V, m.T, mat).mass()).maxCoeff());
    Simulator sim(std::move(scaled));
    const double limit = sim.stable_step_limit();
    const double exact = 2 * std::sqrt(2.0) / omega;  // RK4, undamped
    EXPECT_LE(limit, exact * (1 + 1e-9));
    EXPECT_GT(limit, 0.97 * exact);
    EXPECT_GT(limit, 3 * 2 * std::sqrt(2.0) / omega_plain);  // what the scaling bought
    // A frame from a random velocity field stays finite and bounded in energy.
    MatX3d v = MatX3d::Zero(m.V.rows(), 3);
    for (Eigen::Index i = 0; i < v.rows(); ++i) v.row(i) << std::sin(1.0 * i), std::cos(2.0 * i), 0.1;
    sim.set_velocities(0.01 * v);
    const double e0 = sim.total_energy();
    const AdvanceReport rep = sim.advance(1.0 / 60);
    EXPECT_EQ(rep.retries, 0);
    EXPECT_LE(sim.total_energy(), e0 * (1 + 1e-3));
  }
}

TEST(MassScaling, LowestModesOnlyGoDownAndByLittle) {
  // Lowest 10 elastic frequencies (after the 6 rigid modes) of the free block
  // with and without the added mass (dense). Adding mass can only lower them
  // (Courant-Fischer: exact). How much depends on the added mass's share of
  // each mode's kinetic energy; this mesh is a harsh case (1.1 % of the mass
  // added on 2 surface nodes of a 3-cell block), measured 0.75-3.0 %: the
  // tolerance 4 %. The bunny and dragon figures (0.2-0.3 % added): fem/README.md.
  const Mesh m = block_with_light_nodes({0.03, 0.08});
  const Material mat;
  Model plain(m.V, m.T, mat);
  ModelOptions mo;
  mo.mass_scaling.target_ratio = 0.5;
  Model scaled(m.V, m.T, mat, mo);
  EXPECT_NEAR(scaled.mass_scaling().added_fraction, 0.011, 0.002);
  const Eigen::MatrixXd K = dense_stiffness(plain, m.V);
  const Eigen::VectorXd w0 = dense_eigenvalues(K, plain.mass()).cwiseMax(0).cwiseSqrt();
  const Eigen::VectorXd w1 = dense_eigenvalues(K, scaled.mass()).cwiseMax(0).cwiseSqrt();
  ASSERT_LT(w0[5], 1e-2 * w0[6]);  // six rigid modes (sqrt of round-off)
  for (int k = 6; k < 16; ++k) {
    EXPECT_LE(w1[k], w0[k] * (1 + 1e-9)) << "mode " << k;
    EXPECT_LT((w0[k] - w1[k]) / w0[k], 0.04) << "mode " << k;
  }
}

}  // namespace
}  // namespace icd::fem
