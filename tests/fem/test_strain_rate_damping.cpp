// Strain-rate damping (O'Brien & Hodgins): no damping of rigid velocities,
// forces = minus the gradient of an independently coded Rayleigh dissipation
// function, the affine patch test against the analytic viscous stress, the
// largest damping rate against a dense eigensolver, and explicit stability
// with the damping included in the step limit.
#include <icd/fem/strain_rate_damping.hpp>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <icd/fem/simulator.hpp>
#include "fem_test_utils.hpp"
#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

// Test-side dissipation function R(v) = 1/2 sum V (2 psi |Edot|^2 + phi tr(Edot)^2), Eigen only.
double dissipation_oracle(const TetMeshData& d, const StrainRateDamping& sd, const MatX3d& x,
                          const MatX3d& v) {
  double R = 0;
  for (int e = 0; e < d.num_tets(); ++e) {
    const Eigen::Matrix3d F = d.deformation_gradient(x, e);
    const Eigen::Matrix3d Fdot = d.deformation_gradient(v, e);  // linear in its argument
    const Eigen::Matrix3d Edot = 0.5 * (F.transpose() * Fdot + Fdot.transpose() * F);
    R += 0.5 * d.rest_volume[e] *
         (2 * sd.psi * Edot.squaredNorm() + sd.phi * Edot.trace() * Edot.trace());
  }
  return R;
}

MatX3d damping_force(const TetMeshData& d, const StrainRateDamping& sd, const MatX3d& x,
                     const MatX3d& v) {
  MatX3d f = MatX3d::Zero(d.num_nodes, 3);
  add_strain_rate_damping_forces(d, sd, x, v, f);
  return f;
}

TEST(StrainRateDamping, RigidVelocitiesAreNotDamped) {
  const TetMeshData d = test::box_data(3, 2, 2, {0.3, 0.2, 0.2});
  const StrainRateDamping sd{3.0, 2.0};
  const MatX3d x = d.rest_positions + 0.02 * test::random_field(d.num_nodes, 11);
  const Eigen::Vector3d w(0.3, -1.2, 0.7), t(0.5, 0.1, -0.4);
  MatX3d v(d.num_nodes, 3);
  for (int i = 0; i < d.num_nodes; ++i)
    v.row(i) = (w.cross(Eigen::Vector3d(x.row(i))) + t).transpose();
  MatX3d u = test::random_field(d.num_nodes, 12);
  u *= v.norm() / u.norm();  // a generic velocity of the same size
  const MatX3d generic = damping_force(d, sd, x, u);
  EXPECT_GT(generic.norm(), 0);
  EXPECT_LT(damping_force(d, sd, x, v).norm(), 1e-12 * generic.norm());
  EXPECT_LT(dissipation_oracle(d, sd, x, v), 1e-24 * dissipation_oracle(d, sd, x, u));
}

TEST(StrainRateDamping, ForceIsMinusTheGradientOfTheDissipationFunctionAndDissipates) {
  const TetMeshData d = test::box_data(2, 1, 1, {0.2, 0.1, 0.1});
  const StrainRateDamping sd{1.5, 0.8};
  const MatX3d x = d.rest_positions + 0.02 * test::random_field(d.num_nodes, 13);
  const MatX3d v = test::random_field(d.num_nodes, 14);
  const MatX3d f = damping_force(d, sd, x, v);
  // R is quadratic in v: central differences are exact up to round-off.
  const double h = 1e-3;
  for (int i = 0; i < d.num_nodes; ++i)
    for (int c = 0; c < 3; ++c) {
      MatX3d vp = v, vm = v;
      vp(i, c) += h;
      vm(i, c) -= h;
      const double fd =
          -(dissipation_oracle(d, sd, x, vp) - dissipation_oracle(d, sd, x, vm)) / (2 * h);
      EXPECT_NEAR(f(i, c), fd, 1e-9 * f.cwiseAbs().maxCoeff()) << "node " << i << " axis " << c;
    }
  const double R = dissipation_oracle(d, sd, x, v);
  EXPECT_GT(R, 0);
  EXPECT_NEAR((f.array() * v.array()).sum(), -2 * R, 1e-12 * R);  // power v . f_d = -2 R <= 0
  EXPECT_NEAR(strain_rate_dissipation(d, sd, x, v), R, 1e-12 * R);
}

TEST(StrainRateDamping, AffineVelocityGivesTheAnalyticViscousStress) {
  // x = A X + b, v = B X: F = A, Fdot = B, Edot = sym(A^T B) in every element;
  // S_v = phi tr(Edot) I + 2 psi Edot, P_v = A S_v. The nodal damping forces
  // balance the traction P_v N of the rest boundary faces (as the elastic patch test).
  const Eigen::Vector3d size(0.3, 0.3, 0.3);
  const TetMesh mesh = test::box(3, 3, 3, size);
  const TetMeshData d = make_tet_mesh_data(mesh.V, mesh.T);
  const StrainRateDamping sd{2.0, 0.7};
  Eigen::Matrix3d A, B;
  A << 1.05, 0.02, -0.03, 0.01, 0.97, 0.04, -0.02, 0.03, 1.02;
  B << 0.3, -0.1, 0.2, 0.05, -0.4, 0.1, 0.2, 0.15, 0.25;
  const MatX3d x = (d.rest_positions * A.transpose()).rowwise() + Eigen::RowVector3d(0.1, 0.2, 0.3);
  const MatX3d v = d.rest_positions * B.transpose();
  const Eigen::Matrix3d Edot = 0.5 * (A.transpose() * B + B.transpose() * A);
  const Eigen::Matrix3d P =
      A * (sd.phi * Edot.trace() * Eigen::Matrix3d::Identity() + 2 * sd.psi * Edot);
  MatX3d expected = MatX3d::Zero(d.num_nodes, 3);
  for (int k = 0; k < mesh.F.rows(); ++k) {
    const Eigen::Vector3d X0 = mesh.V.row(mesh.F(k, 0)), X1 = mesh.V.row(mesh.F(k, 1)),
                          X2 = mesh.V.row(mesh.F(k, 2));
    const Eigen::Vector3d area_normal = 0.5 * (X1 - X0).cross(X2 - X0);
    for (int a = 0; a < 3; ++a) expected.row(mesh.F(k, a)) -= (P * area_normal / 3.0).transpose();
  }
  const MatX3d f = damping_force(d, sd, x, v);
  EXPECT_LT((f - expected).cwiseAbs().maxCoeff(), 1e-12 * P.norm() * 0.01);
  EXPECT_NEAR(
      strain_rate_dissipation(d, sd, x, v),
      0.5 * size.prod() * (2 * sd.psi * Edot.squaredNorm() + sd.phi * Edot.trace() * Edot.trace()),
      1e-12 * size.prod() * P.norm());
}

TEST(StrainRateDamping, LargestDampingRateMatchesDenseEigenvalues) {
  ModelOptions mo;
  mo.strain_rate_damping = {40.0, 25.0};
  const TetMesh m = test::box(4, 1, 1, {0.4, 0.1, 0.1});
  Model model(m.V, m.T, test::material(MaterialModel::StVK), mo);
  model.set_fixed_nodes({0, 1});
  MatX3d x = m.V;
  x.col(0) *= 0.7;  // compressed
  // Dense D on the free dofs, column by column: D e_j = -f_d(e_j).
  std::vector<int> free;
  for (int i = 0; i < model.num_nodes(); ++i)
    if (!model.fixed_nodes()[i])
      for (int c = 0; c < 3; ++c) free.push_back(3 * i + c);
  const int n = static_cast<int>(free.size());
  Eigen::MatrixXd D(n, n), M = Eigen::MatrixXd::Zero(n, n);
  for (int b = 0; b < n; ++b) {
    MatX3d u = MatX3d::Zero(model.num_nodes(), 3);
    u(free[b] / 3, free[b] % 3) = 1.0;
    const MatX3d f = damping_force(model.mesh(), mo.strain_rate_damping, x, u);
    for (int a = 0; a < n; ++a) D(a, b) = -f(free[a] / 3, free[a] % 3);
    M(b, b) = model.mass()[free[b] / 3];
  }
  EXPECT_LT((D - D.transpose()).norm(), 1e-10 * D.norm());
  // The assembled matrix (backward Euler's) equals the columns of the force map.
  Eigen::SparseMatrix<double> A = model.elastic().pattern().zero_matrix();
  add_strain_rate_damping_matrix(model.mesh(), model.elastic().pattern(), mo.strain_rate_damping, x,
                                 1.0, A);
  const Eigen::MatrixXd Ad = Eigen::MatrixXd(A);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) EXPECT_NEAR(Ad(free[a], free[b]), D(a, b), 1e-12 * D.norm());
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(D, M, Eigen::EigenvaluesOnly);
  EXPECT_GT(es.eigenvalues().minCoeff(),
            -1e-9 * es.eigenvalues().maxCoeff());  // positive semi-definite
  const double c = estimate_max_damping_rate(model, x, {});
  EXPECT_NEAR(c, es.eigenvalues().maxCoeff(), 1e-4 * c);
  EXPECT_GE(
      c, es.eigenvalues().maxCoeff() * (1 - 1e-12));  // the residual bound is an upper bound here
}

TEST(StrainRateDamping, ExplicitStepsAreStableWithTheDampingInTheLimit) {
  // Viscosity strong enough to bind the step (the limit is less than half the
  // undamped one): 0.99 x the limit decays, 1.5 x blows up.
  for (Integrator integ : {Integrator::SymplecticEuler, Integrator::RK4}) {
    ModelOptions mo;
    mo.strain_rate_damping = {0.0, 2000.0};
    const TetMesh m = test::box(10, 1, 1);
    Model model(m.V, m.T, test::material(MaterialModel::StVK, 1e6, 0.3), mo);
    std::vector<int> fixed;
    for (int i = 0; i < m.V.rows(); ++i)
      if (m.V(i, 0) < 1e-12) fixed.push_back(i);
    model.set_fixed_nodes(fixed);
    const double omega = estimate_max_frequency(model, m.V, {}).omega_bound;
    const double c = estimate_max_damping_rate(model, m.V, {});
    const double undamped = stable_step_limit(integ, omega, {});
    const double limit = stable_step_limit(integ, omega, {}, c);
    EXPECT_LT(limit, 0.5 * undamped) << to_string(integ) << " c " << c << " omega " << omega;
    if (integ == Integrator::SymplecticEuler) {
      EXPECT_LE(limit, 2.0 / c * (1 + 1e-12));
    }
    auto run = [&](double h) {
      State s{m.V + 0.01 * test::random_field(model.num_nodes(), 5),
              MatX3d::Zero(model.num_nodes(), 3)};
      for (int i : fixed) s.x.row(i) = m.V.row(i);
      ExplicitStepper stepper;
      const double e0 = model.elastic().energy(s.x);
      double e = e0;
      for (int k = 0; k < 400 && std::isfinite(e) && e < 1e6 * e0; ++k) {
        if (integ == Integrator::RK4)
          stepper.rk4(model, s, h);
        else
          stepper.symplectic_euler(model, s, h);
        e = model.kinetic_energy(s.v) + model.elastic().energy(s.x);
      }
      return e / e0;
    };
    EXPECT_LT(run(0.99 * limit), 1.0) << to_string(integ);
    EXPECT_GT(run(1.5 * limit), 1e3) << to_string(integ);
  }
}

TEST(StrainRateDamping, SimulatorStepsStayStableAndDissipateForEveryIntegrator) {
  // Through the Simulator: automatic steps include the damping rate in the
  // limit (explicit), Newton includes h D (backward Euler, few iterations);
  // without gravity and loads, KE + W only decreases from a perturbed state.
  for (Integrator integ :
       {Integrator::RK4, Integrator::SymplecticEuler, Integrator::BackwardEuler}) {
    ModelOptions mo;
    mo.strain_rate_damping = {500.0, 1000.0};
    const TetMesh m = test::box(10, 1, 1);
    Model model(m.V, m.T, test::material(MaterialModel::StVK, 1e6, 0.3), mo);
    std::vector<int> fixed;
    for (int i = 0; i < m.V.rows(); ++i)
      if (m.V(i, 0) < 1e-12) fixed.push_back(i);
    model.set_fixed_nodes(fixed);
    SimulatorOptions so;
    so.integrator = integ;
    so.max_step = 1.0 / 240;
    Simulator sim(std::move(model), so);
    MatX3d v = 0.5 * test::random_field(sim.model().num_nodes(), 8);
    sim.set_velocities(v);
    double e = sim.total_energy();
    for (int f = 0; f < 6; ++f) {
      const AdvanceReport rep = sim.advance(1.0 / 60);
      EXPECT_EQ(rep.retries, 0) << to_string(integ);
      const double e1 = sim.total_energy();
      EXPECT_LT(e1, e) << to_string(integ) << " frame " << f;
      e = e1;
    }
  }
}

TEST(StrainRateDamping, RejectsNegativeOrNonFiniteViscosity) {
  const TetMesh m = test::box(1, 1, 1);
  ModelOptions mo;
  mo.strain_rate_damping.phi = -1;
  EXPECT_THROW(Model(m.V, m.T, test::material(MaterialModel::StVK), mo), ParameterError);
  mo.strain_rate_damping = {0.0, std::numeric_limits<double>::quiet_NaN()};
  try {
    Model(m.V, m.T, test::material(MaterialModel::StVK), mo);
    ADD_FAILURE();
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("psi"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace icd::fem
