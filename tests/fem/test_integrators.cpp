// Dynamics against references: damped motion settles to the CHOLMOD static
// solution, symplectic Euler conserves energy, the oscillation period matches
// the discrete eigenfrequency.
#include <icd/fem/integrators.hpp>

#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <icd/fem/simulator.hpp>
#include <icd/fem/static_solver.hpp>
#include "fem_test_utils.hpp"

namespace icd::fem {
namespace {

// Relative difference of two deformed configurations, over the displacement norm.
double relative_difference(const MatX3d& a, const MatX3d& b, const MatX3d& rest) {
  return (a - b).norm() / (b - rest).norm();
}

TEST(Integrators, DampedDynamicsSettleToTheStaticSolution) {
  // StVK cantilever, E = 1e7: tip deflection ~7% of L, so geometric
  // nonlinearity matters and Newton needs several iterations.
  const Material mat = test::material(MaterialModel::StVK, 1e7, 0.3);
  Model ref = test::cantilever(2, mat);
  MatX3d x_static = ref.mesh().rest_positions;
  StaticSolver solver;
  ASSERT_TRUE(solver.solve(ref, x_static).converged);
  // First mode ~2 Hz (omega_1 ~ 13 rad/s): alpha = 26/s damps it critically,
  // the residual after 1.5 s is ~exp(-13 * 1.5) ~ 1e-8 of the initial error.
  for (Integrator integ :
       {Integrator::RK4, Integrator::SymplecticEuler, Integrator::BackwardEuler}) {
    SimulatorOptions o;
    o.integrator = integ;
    o.max_step = 2e-3;  // backward Euler: small enough not to matter for the end state
    Simulator sim(test::cantilever(2, mat, 9.81, {26.0, 0.0}), o);
    for (int frame = 0; frame < 90; ++frame) sim.advance(1.0 / 60);
    EXPECT_LT(relative_difference(sim.positions(), x_static, ref.mesh().rest_positions), 0.005)
        << to_string(integ);
    EXPECT_LT(sim.velocities().cwiseAbs().maxCoeff(), 1e-3) << to_string(integ);
  }
}

TEST(Integrators, SymplecticEulerKeepsEnergyWithinOnePercentOver10000Steps) {
  const Material mat = test::material(MaterialModel::StVK, 1e6, 0.3);
  // Initial state: static deflection under gravity (a smooth, large-amplitude
  // bending shape: tip ~ 0.2 m), then released with gravity off and no damping.
  Model model = test::cantilever(1, mat);
  MatX3d x0 = model.mesh().rest_positions;
  StaticSolver solver;
  ASSERT_TRUE(solver.solve(model, x0).converged);
  model.set_gravity(Eigen::Vector3d::Zero());
  State s{x0, MatX3d::Zero(model.num_nodes(), 3)};
  const double h = 0.9 * stable_step_limit(Integrator::SymplecticEuler,
                                           estimate_max_frequency(model, x0, {}).omega_max, {});
  const double e0 = model.elastic().energy(s.x);
  ExplicitStepper stepper;
  double worst = 0;
  for (int k = 0; k < 10000; ++k) {
    stepper.symplectic_euler(model, s, h);
    const double e = model.kinetic_energy(s.v) + model.elastic().energy(s.x);
    worst = std::max(worst, std::abs(e - e0) / e0);
  }
  EXPECT_LT(worst, 0.01);
  EXPECT_GT(h * 10000, 0.3);  // several oscillation periods (period ~0.2 s)
}

// Frequency of q(t) = phi^T M (x(t) - X), by upward zero crossings (linear interpolation).
double measured_frequency(Integrator integ, Model& model, const MatX3d& x0, const MatX3d& phi,
                          double h, double duration) {
  State s{x0, MatX3d::Zero(model.num_nodes(), 3)};
  const MatX3d& X = model.mesh().rest_positions;
  auto q = [&](const MatX3d& x) {
    return ((x - X).cwiseProduct(phi).rowwise().sum().array() * model.mass().array()).sum();
  };
  ExplicitStepper stepper;
  BackwardEulerStepper implicit;
  std::vector<double> crossings;
  double prev = q(s.x);
  for (int k = 1; k * h <= duration; ++k) {
    if (integ == Integrator::RK4)
      stepper.rk4(model, s, h);
    else if (integ == Integrator::SymplecticEuler)
      stepper.symplectic_euler(model, s, h);
    else
      implicit.step(model, s, h);
    const double z = q(s.x);
    if (prev < 0 && z >= 0) crossings.push_back((k - 1) * h + h * (-prev) / (z - prev));
    prev = z;
  }
  if (crossings.size() < 2) return 0;
  return (crossings.size() - 1) / (crossings.back() - crossings.front());
}

TEST(Integrators, OscillationFrequencyMatchesTheDiscreteEigenfrequency) {
  // Linear material: released from the first eigenmode of the dense generalized
  // eigensolver (the oracle, for this very mesh), the motion is that single
  // mode. RK4 and symplectic Euler at 0.9x their stable steps have relative
  // phase errors O((h omega_1)^2) ~ 1e-6; the crossing interpolation error is
  // of the same order. Tolerance 0.1%.
  const Material mat = test::material(MaterialModel::Linear, 1e7, 0.3);
  Model model = test::cantilever(1, mat, 0.0);
  const MatX3d& X = model.mesh().rest_positions;
  const Eigen::MatrixXd K = Eigen::MatrixXd(model.elastic().stiffness(X));
  std::vector<int> free;
  for (int i = 0; i < model.num_nodes(); ++i)
    if (!model.fixed_nodes()[i])
      for (int c = 0; c < 3; ++c) free.push_back(3 * i + c);
  const int n = static_cast<int>(free.size());
  Eigen::MatrixXd Kf(n, n), Mf = Eigen::MatrixXd::Zero(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) Kf(a, b) = K(free[a], free[b]);
    Mf(a, a) = model.mass()[free[a] / 3];
  }
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Kf, Mf);
  const double f1 = std::sqrt(es.eigenvalues()[0]) / (2 * M_PI);
  MatX3d phi = MatX3d::Zero(model.num_nodes(), 3);
  for (int a = 0; a < n; ++a) phi(free[a] / 3, free[a] % 3) = es.eigenvectors()(a, 0);
  phi *= 0.01 / phi.cwiseAbs().maxCoeff();  // 1 cm amplitude
  const MatX3d x0 = X + phi;
  const double omega_max = estimate_max_frequency(model, X, {}).omega_max;
  for (Integrator integ : {Integrator::RK4, Integrator::SymplecticEuler}) {
    const double h = 0.9 * stable_step_limit(integ, omega_max, {});
    const double f = measured_frequency(integ, model, x0, phi, h, 6.0 / f1);
    EXPECT_NEAR(f, f1, 1e-3 * f1) << to_string(integ);
  }
  // Backward Euler at h = T1/100: the discrete frequency is
  // atan(h omega) / h / (2 pi) -> 0.66% low (its damping does not shift crossings).
  const double hb = 0.01 / f1, w = 2 * M_PI * f1;
  const double fb = measured_frequency(Integrator::BackwardEuler, model, x0, phi, hb, 4.0 / f1);
  EXPECT_NEAR(fb, std::atan(hb * w) / hb / (2 * M_PI), 1e-3 * f1);
}

// A cantilever with every nodal term of the node pass: fixed nodes, gravity,
// external forces, Rayleigh alpha (and, with `element_damping`, beta and the
// strain-rate damping, which add element passes), at a random state.
struct FusedCase {
  Model model;
  State in;
};

FusedCase fused_case(bool element_damping) {
  const Material mat = test::material(MaterialModel::StVK, 1e6, 0.3);
  Model model = test::cantilever(1, mat, 9.81, {2.0, element_damping ? 1e-4 : 0.0});
  if (element_damping) model.set_strain_rate_damping({1.0, 2.0});
  const int n = model.num_nodes();
  model.set_external_forces(test::random_field(n, 3));
  State in{model.mesh().rest_positions + 0.01 * test::random_field(n, 1),
           0.1 * test::random_field(n, 2)};
  for (int i = 0; i < n; ++i)
    if (model.fixed_nodes()[i]) in.v.row(i).setZero();
  return {std::move(model), std::move(in)};
}

TEST(Integrators, FusedSymplecticEulerNodePassEqualsAccelerationThenUpdate) {
  // One node pass forms a, v1, x1 and the input's energies: the state must be
  // bitwise that of Model::acceleration followed by v1 = v + h a, x1 = x + h v1;
  // the energies those of Model::kinetic_energy / load_potential (other
  // summation order: equal to rounding); the health that of the separate pass.
  for (bool element_damping : {false, true}) {
    FusedCase c = fused_case(element_damping);
    const int n = c.model.num_nodes();
    const double h = 1e-4;
    MatX3d a(n, 3);
    c.model.acceleration(c.in.x, c.in.v, a);
    const MatX3d v1 = c.in.v + h * a;
    const MatX3d x1 = c.in.x + h * v1;
    ExplicitStepper stepper;
    State out;
    ElementHealth health;
    StateEnergies energies;
    StepExtras extras;
    extras.health = &health;
    extras.energies = &energies;
    stepper.symplectic_euler(c.model, c.in, out, h, extras);
    EXPECT_TRUE(out.v.cwiseEqual(v1).all()) << element_damping;
    EXPECT_TRUE(out.x.cwiseEqual(x1).all()) << element_damping;
    const double ke = c.model.kinetic_energy(c.in.v), lp = c.model.load_potential(c.in.x);
    ASSERT_GT(ke, 0);
    EXPECT_NEAR(energies.kinetic, ke, 1e-14 * ke);
    EXPECT_NEAR(energies.load, lp, 1e-14 * std::abs(lp));
    const StateEnergies plain = state_energies(c.model, c.in);
    EXPECT_EQ(plain.kinetic, energies.kinetic);
    EXPECT_EQ(plain.load, energies.load);
    const ElementHealth ref = c.model.elastic().health(c.in.x);
    EXPECT_NEAR(health.energy, ref.energy, 1e-12 * ref.energy);
    EXPECT_EQ(health.min_det_f_element, ref.min_det_f_element);
    // Fixed nodes stay exactly where they are.
    for (int i = 0; i < n; ++i)
      if (c.model.fixed_nodes()[i]) {
        EXPECT_TRUE(out.x.row(i) == c.in.x.row(i)) << i;
      }
  }
}

TEST(Integrators, GivenElasticForcesReplaceTheFirstEvaluationBitwise) {
  // StepExtras::elastic (f_int(x) from a health check at x) gives the state of
  // a step that evaluates it, for both integrators and with element damping.
  for (bool element_damping : {false, true}) {
    FusedCase c = fused_case(element_damping);
    const int n = c.model.num_nodes();
    MatX3d f(n, 3);
    c.model.elastic().compute(c.in.x, f);
    for (Integrator integ : {Integrator::RK4, Integrator::SymplecticEuler}) {
      ExplicitStepper stepper;
      State out[2];
      for (int k = 0; k < 2; ++k) {
        StepExtras extras;
        StateEnergies energies;
        extras.energies = &energies;
        if (k == 1) extras.elastic = &f;
        if (integ == Integrator::RK4)
          stepper.rk4(c.model, c.in, out[k], 1e-4, extras);
        else
          stepper.symplectic_euler(c.model, c.in, out[k], 1e-4, extras);
        EXPECT_NEAR(energies.kinetic, c.model.kinetic_energy(c.in.v), 1e-14 * energies.kinetic);
      }
      EXPECT_TRUE(out[0].x.cwiseEqual(out[1].x).all()) << to_string(integ) << element_damping;
      EXPECT_TRUE(out[0].v.cwiseEqual(out[1].v).all()) << to_string(integ) << element_damping;
      EXPECT_GT((out[0].x - c.in.x).cwiseAbs().maxCoeff(), 0.0);
    }
  }
}

TEST(Integrators, StateEnergiesAreNotFiniteForANonFiniteEntry) {
  // The health check relies on it: every entry of x and v enters the sums,
  // also where the load or the mass weight is zero (0 * inf = NaN).
  FusedCase c = fused_case(false);
  const double inf = std::numeric_limits<double>::infinity();
  int fixed_node = -1;
  for (int i = 0; i < c.model.num_nodes(); ++i)
    if (c.model.fixed_nodes()[i]) fixed_node = i;
  ASSERT_GE(fixed_node, 0);
  c.model.set_external_forces(MatX3d::Zero(c.model.num_nodes(), 3));  // load only along z
  EXPECT_TRUE(std::isfinite(state_energies(c.model, c.in).kinetic));
  for (int k = 0; k < 3; ++k) {
    State s = c.in;
    if (k == 0) s.v(7, 1) = std::numeric_limits<double>::quiet_NaN();
    if (k == 1) s.x(7, 0) = inf;            // no load along x
    if (k == 2) s.x(fixed_node, 1) = -inf;  // no load at a fixed node
    const StateEnergies e = state_energies(c.model, s);
    EXPECT_FALSE(std::isfinite(e.kinetic) && std::isfinite(e.load)) << k;
  }
}

}  // namespace
}  // namespace icd::fem
