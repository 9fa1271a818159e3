// Simulator: the fixed-step guard, automatic sub-stepping on stiff and
// extreme cases, health checks with rollback, retries and diagnostics.
#include <icd/fem/simulator.hpp>

#include <memory>

#include <gtest/gtest.h>

#include "fem_test_utils.hpp"
#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

TEST(Simulator, FixedStepAboveTheLimitIsRefusedNamingTheLimit) {
  for (Integrator integ : {Integrator::RK4, Integrator::SymplecticEuler}) {
    const Material mat = test::material(MaterialModel::StVK, 1e7, 0.3);
    SimulatorOptions po;
    po.integrator = integ;
    Simulator probe(test::cantilever(1, mat), po);
    const double limit = probe.stable_step_limit();
    SimulatorOptions o;
    o.integrator = integ;
    o.fixed_step = 1.05 * limit;
    Simulator over(test::cantilever(1, mat), o);
    try {
      over.advance(0.01);
      ADD_FAILURE() << "1.05x the limit was accepted";
    } catch (const ParameterError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("stable step limit"), std::string::npos) << msg;
      EXPECT_NE(msg.find(std::to_string(limit).substr(0, 5)), std::string::npos)
          << msg << " vs " << limit;
    }
    EXPECT_THROW(over.step(1.05 * limit), ParameterError);
    // Later frames re-estimate with a few warm Lanczos products and take the
    // residual upper bound (and the sagging beam's omega_max moves), so their
    // limit can be ~1% below the converged first one: 0.97 x stays under it.
    o.fixed_step = 0.97 * limit;
    Simulator under(test::cantilever(1, mat), o);
    for (int f = 0; f < 30; ++f) under.advance(1.0 / 60);
    EXPECT_TRUE(under.positions().allFinite());
    EXPECT_LT(test::tip_deflection(under.model(), under.positions()), 0.0);  // it sags
  }
}

// Runs frames with automatic steps; returns the reports.
std::vector<AdvanceReport> run(Simulator& sim, int frames) {
  std::vector<AdvanceReport> reps;
  for (int f = 0; f < frames; ++f) reps.push_back(sim.advance(1.0 / 60));
  return reps;
}

TEST(Simulator, StiffAndNearlyIncompressibleMaterialsRunWithAutomaticSteps) {
  for (MaterialModel mm : test::all_models())
    for (auto [E, nu] : {std::pair{1e9, 0.3}, std::pair{1e6, 0.49}, std::pair{1e9, 0.49}}) {
      SimulatorOptions o;
      o.integrator = Integrator::SymplecticEuler;
      Simulator sim(test::cantilever(1, test::material(mm, E, nu)), o);
      const auto reps = run(sim, 3);
      EXPECT_TRUE(sim.positions().allFinite()) << to_string(mm);
      // The step chosen is safety x limit, and the limit ~ 2 / omega_max.
      EXPECT_NEAR(reps[0].step, 0.9 * reps[0].step_limit, 0.01 * reps[0].step_limit)
          << to_string(mm);
      EXPECT_NEAR(reps[0].step_limit * reps[0].omega_max, 2.0, 1e-6);
      EXPECT_GT(reps[0].substeps, 10);
    }
}

TEST(Simulator, ReleaseFrom70PercentCompressionStaysFinite) {
  // A free cube squeezed to 30% of its height along z, then released: violent
  // expansion, automatic steps with the frequency re-estimated each frame,
  // health checks on. The inversion-safe model must come through (inversion
  // allowed by policy Auto); corotational too when inversion is allowed.
  // StVK is not inversion-safe: it may stop, but only with a NumericalError
  // naming the element, never with NaN positions.
  for (MaterialModel mm :
       {MaterialModel::StableNeoHookean, MaterialModel::Corotational, MaterialModel::StVK}) {
    const TetMesh m = test::box(4, 4, 4, {0.2, 0.2, 0.2});
    Model model(m.V, m.T, test::material(mm, 1e6, 0.45));
    MatX3d x = m.V;
    x.col(2) *= 0.3;
    SimulatorOptions o;
    o.integrator = Integrator::RK4;
    if (mm == MaterialModel::Corotational) o.inversion = InversionPolicy::Allow;
    Simulator sim(std::move(model), o);
    sim.set_positions(x);
    std::vector<AdvanceReport> reps;
    try {
      reps = run(sim, 6);
    } catch (const NumericalError& e) {
      EXPECT_EQ(mm, MaterialModel::StVK) << e.what();
      EXPECT_NE(std::string(e.what()).find("element"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(sim.positions().allFinite()) << to_string(mm);
    EXPECT_TRUE(sim.velocities().allFinite()) << to_string(mm);
    if (mm == MaterialModel::StVK) continue;
    ASSERT_EQ(reps.size(), 6u);
    // It expanded back towards its rest height 0.2 m.
    const double height = sim.positions().col(2).maxCoeff() - sim.positions().col(2).minCoeff();
    EXPECT_GT(height, 0.1) << to_string(mm);
  }
}

TEST(Simulator, BackwardEulerTakesLargeStepsOnStiffMaterial) {
  SimulatorOptions o;
  o.integrator = Integrator::BackwardEuler;
  o.max_step = 1.0 / 60;
  Simulator sim(test::cantilever(1, test::material(MaterialModel::StVK, 1e9, 0.49)), o);
  const auto reps = run(sim, 5);
  EXPECT_EQ(reps[0].substeps, 1);
  EXPECT_TRUE(sim.positions().allFinite());
}

TEST(Simulator, HealthCheckRollsBackAndRetriesThenNamesTheElement) {
  // A node shot through its neighbours inverts elements whatever the step;
  // StVK with inversion checks on fails after the bounded retries, and the
  // diagnostic names the element, its nodes and det F.
  const Material mat = test::material(MaterialModel::StVK, 1e6, 0.3);
  SimulatorOptions o;
  o.integrator = Integrator::SymplecticEuler;
  o.max_retries = 3;
  Simulator sim(test::cantilever(1, mat, 0.0), o);
  MatX3d v = MatX3d::Zero(sim.model().num_nodes(), 3);
  const int node = sim.model().num_nodes() - 1;
  v(node, 0) = -200.0;  // 0.1 m cell crossed in 0.5 ms
  sim.set_velocities(v);
  try {
    sim.advance(1.0 / 60);
    ADD_FAILURE() << "no failure";
  } catch (const NumericalError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("element"), std::string::npos) << msg;
    EXPECT_NE(msg.find("det F"), std::string::npos) << msg;
    EXPECT_NE(msg.find("3 retries"), std::string::npos) << msg;
  }
  // The state is the last good one: finite.
  EXPECT_TRUE(sim.positions().allFinite());
  EXPECT_TRUE(sim.velocities().allFinite());
}

TEST(Simulator, ChecksDoNotChangeTheTrajectory) {
  // The health checks ride on the force passes (every step) or run every 4th
  // step: the trajectory is the same, bitwise, for both integrators; the
  // reported sub-step counts are equal.
  for (Integrator integ : {Integrator::RK4, Integrator::SymplecticEuler}) {
    const Material mat = test::material(MaterialModel::StVK, 1e6, 0.3);
    MatX3d x[2];
    int substeps[2];
    for (int k = 0; k < 2; ++k) {
      SimulatorOptions o;
      o.integrator = integ;
      o.check_interval = k == 0 ? 1 : 4;
      Simulator sim(test::cantilever(1, mat), o);
      substeps[k] = 0;
      for (int f = 0; f < 5; ++f) substeps[k] += sim.advance(1.0 / 60).substeps;
      x[k] = sim.positions();
    }
    EXPECT_TRUE(x[0].cwiseEqual(x[1]).all()) << to_string(integ);
    EXPECT_EQ(substeps[0], substeps[1]);
    EXPECT_LT(test::tip_deflection(test::cantilever(1, mat), x[0]), 0.0);
  }
}

TEST(Simulator, RejectsBadOptionsAndInputs) {
  const Material mat = test::material(MaterialModel::StVK);
  SimulatorOptions o;
  o.safety_factor = 1.5;
  EXPECT_THROW(Simulator(test::cantilever(1, mat), o), ParameterError);
  Simulator sim(test::cantilever(1, mat));
  MatX3d f = MatX3d::Zero(sim.model().num_nodes(), 3);
  f(5, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    sim.set_external_forces(f);
    ADD_FAILURE();
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("node 5"), std::string::npos) << e.what();
  }
  EXPECT_THROW(sim.advance(0.0), ParameterError);
  EXPECT_THROW(sim.set_positions(MatX3d::Zero(3, 3)), ParameterError);
}

TEST(Simulator, FrameEndForcesReusedGiveTheTrajectoryOfPlainSteps) {
  // advance() reuses f_int of the frame's end state (from its final health
  // check) for the next frame's first step: with a fixed step the trajectory
  // must be bitwise that of plain ExplicitStepper steps of the same sizes,
  // also across set_positions() (which must drop the reused forces).
  const Material mat = test::material(MaterialModel::StVK, 1e6, 0.3);
  for (Integrator integ : {Integrator::RK4, Integrator::SymplecticEuler}) {
    SimulatorOptions o;
    o.integrator = integ;
    o.fixed_step = 2e-4;
    Simulator sim(test::cantilever(1, mat), o);
    Model model = test::cantilever(1, mat);
    State s{model.mesh().rest_positions, MatX3d::Zero(model.num_nodes(), 3)};
    ExplicitStepper stepper;
    const double frame = 1.0 / 60;
    for (int f = 0; f < 6; ++f) {
      if (f == 3) {  // moved by the user: the forces of the old end state are stale
        s.x = sim.positions() + 1e-3 * test::random_field(model.num_nodes(), 4);
        for (int i = 0; i < model.num_nodes(); ++i)
          if (model.fixed_nodes()[i]) s.x.row(i) = model.mesh().rest_positions.row(i);
        sim.set_positions(s.x);
      }
      const int substeps = sim.advance(frame).substeps;
      // The Simulator's sub-steps: equal pieces of what is left of the frame.
      double t = 0;
      int count = 0;
      while (t < frame) {
        const int remaining = static_cast<int>(std::ceil((frame - t) / o.fixed_step * (1 - 1e-12)));
        const double hh = (frame - t) / std::max(remaining, 1);
        if (integ == Integrator::RK4)
          stepper.rk4(model, s, hh);
        else
          stepper.symplectic_euler(model, s, hh);
        t = remaining <= 1 ? frame : t + hh;
        ++count;
      }
      EXPECT_EQ(substeps, count);
      EXPECT_TRUE(sim.positions().cwiseEqual(s.x).all()) << to_string(integ) << " frame " << f;
      EXPECT_TRUE(sim.velocities().cwiseEqual(s.v).all()) << to_string(integ) << " frame " << f;
    }
    EXPECT_LT(test::tip_deflection(model, s.x), 0.0);
  }
}

TEST(Simulator, BoundChecksGiveTheTrajectoryOfFullChecks) {
  // EnergyCheck::Bound (the default for StVK) and Full check different
  // quantities, never the state: on a run that passes both, the trajectory
  // and the sub-step counts are bitwise equal.
  for (Integrator integ : {Integrator::RK4, Integrator::SymplecticEuler}) {
    const Material mat = test::material(MaterialModel::StVK, 1e6, 0.3);
    MatX3d x[2];
    int substeps[2], retries[2];
    for (int k = 0; k < 2; ++k) {
      SimulatorOptions o;
      o.integrator = integ;
      o.energy_check = k == 0 ? EnergyCheck::Bound : EnergyCheck::Full;
      Simulator sim(test::cantilever(1, mat), o);
      substeps[k] = retries[k] = 0;
      for (int f = 0; f < 5; ++f) {
        const AdvanceReport r = sim.advance(1.0 / 60);
        substeps[k] += r.substeps;
        retries[k] += r.retries;
      }
      x[k] = sim.positions();
    }
    EXPECT_TRUE(x[0].cwiseEqual(x[1]).all()) << to_string(integ);
    EXPECT_EQ(substeps[0], substeps[1]);
    EXPECT_EQ(retries[0], 0);
    EXPECT_EQ(retries[1], 0);
    EXPECT_LT(test::tip_deflection(test::cantilever(1, mat), x[0]), 0.0);
  }
}

// A symplectic Euler run whose steps exceed the stable limit: the limit is
// estimated without damping and kept (frequency_reuse_time), then stiffness
// damping beta = q / omega_max is switched on, which lowers the limit of the
// top mode to r = (sqrt(q^2 + 4) - q) / 2 of the undamped one (the Jury
// condition; q = (1 - r^2) / r), so that the automatic steps, 0.9 x the
// undamped limit, are `overshoot` x the damped one.
struct UnstableRun {
  std::unique_ptr<Simulator> sim;
  double h = 0;  ///< the automatic step, s
};
UnstableRun unstable_run(EnergyCheck check, double overshoot, int max_retries) {
  SimulatorOptions o;
  o.integrator = Integrator::SymplecticEuler;
  o.energy_check = check;
  o.max_retries = max_retries;
  o.frequency_reuse_time = 1e9;
  o.frequency_reuse_strain = std::numeric_limits<double>::infinity();  // frozen: no re-estimate
  UnstableRun u{std::make_unique<Simulator>(
      test::cantilever(1, test::material(MaterialModel::StVK, 1e7, 0.3), 0.0), o)};
  const int n = u.sim->model().num_nodes();
  u.sim->set_velocities(1e-3 * test::random_field(n, 7));  // all modes excited
  const double limit = u.sim->stable_step_limit();
  const double omega = u.sim->last_frequency().omega_bound;
  const double r = 0.9 / overshoot;
  const RayleighDamping damping{0.0, (1 - r * r) / r / omega};
  EXPECT_NEAR(stable_step_limit(Integrator::SymplecticEuler, omega, damping), r * limit,
              1e-6 * limit);
  u.sim->model().set_damping(damping);
  u.h = 0.9 * limit;
  return u;
}

// Simulated time of the state a NumericalError rejected ("... at t = T s").
double failure_time(const std::string& message) {
  const size_t at = message.find("at t = ");
  return at == std::string::npos ? -1.0 : std::stod(message.substr(at + 7));
}

TEST(Simulator, BoundCheckCatchesAnUnstableStepWithinAFewStepsOfTheFullCheck) {
  // Steps 1.3x above the (damped) limit; no retries, so the first failed
  // check throws. The bound (kinetic energy + load potential against the
  // frame start's total energy, det F > 0) must catch the blow-up no more
  // than 3 steps after the full check (total energy against the previous
  // step) does, and both must leave the last good, finite state.
  double t[2];
  for (int k = 0; k < 2; ++k) {
    UnstableRun u = unstable_run(k == 0 ? EnergyCheck::Bound : EnergyCheck::Full, 1.3, 0);
    const double e0 = u.sim->total_energy();
    t[k] = -1;
    for (int f = 0; f < 30 && t[k] < 0; ++f) {
      try {
        u.sim->advance(1.0 / 60);
      } catch (const NumericalError& e) {
        t[k] = failure_time(e.what());
        EXPECT_NE(std::string(e.what()).find("energy grew"), std::string::npos) << e.what();
      }
    }
    ASSERT_GT(t[k], 0.0) << "no failure, k = " << k;
    // Inside the first frame, well before its end (where the full check
    // runs in either mode): the check inside the frame caught it.
    EXPECT_LT(t[k], 1.0 / 60 - 5 * u.h) << "k = " << k;
    EXPECT_TRUE(u.sim->positions().allFinite());
    EXPECT_TRUE(u.sim->velocities().allFinite());
    EXPECT_LT(u.sim->total_energy(), 10 * e0);  // rolled back before the blow-up
    if (k == 1) {
      EXPECT_LE(t[0], t[1] + 3 * u.h) << "bound at " << t[0] << " s, full at " << t[1] << " s";
    }
  }
}

TEST(Simulator, BoundCheckRetriesWithHalvedStepsThroughAnUnstableRun) {
  // The same run with retries: every frame's first try blows up and is
  // caught; halving the step makes it stable (0.65x the damped limit).
  UnstableRun u = unstable_run(EnergyCheck::Bound, 1.3, 6);
  const double e0 = u.sim->total_energy();
  int retries = 0;
  for (int f = 0; f < 4; ++f) retries += u.sim->advance(1.0 / 60).retries;
  EXPECT_GE(retries, 1);
  EXPECT_TRUE(u.sim->positions().allFinite());
  EXPECT_LE(u.sim->total_energy(), 1.0001 * e0);  // damped: no energy is created
}

TEST(Simulator, OverflowingStateStopsBothChecksWithAFiniteState) {
  // A node shot at 1e150 m/s: within a step or two the positions, forces and
  // velocities overflow to Inf/NaN. Both checks must stop with a
  // NumericalError and leave a finite state (never NaN positions).
  for (EnergyCheck check : {EnergyCheck::Bound, EnergyCheck::Full}) {
    SimulatorOptions o;
    o.integrator = Integrator::SymplecticEuler;
    o.energy_check = check;
    o.max_retries = 2;
    Simulator sim(test::cantilever(1, test::material(MaterialModel::StVK, 1e6, 0.3), 0.0), o);
    MatX3d v = MatX3d::Zero(sim.model().num_nodes(), 3);
    v(sim.model().num_nodes() - 1, 2) = 1e150;
    sim.set_velocities(v);
    EXPECT_THROW(sim.advance(1.0 / 60), NumericalError);
    EXPECT_TRUE(sim.positions().allFinite());
    EXPECT_TRUE(sim.velocities().allFinite());
  }
}

}  // namespace
}  // namespace icd::fem
