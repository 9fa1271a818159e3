// Determinism of the element loops: bitwise-identical results for 1 and 2
// threads (forces, energy, differential, and whole simulations) and for the
// baseline and AVX2 builds of the lane loops.
#include <cstring>

#include <gtest/gtest.h>

#include <icd/fem/forces.hpp>
#include <icd/fem/lane_loops.hpp>
#include <icd/fem/simulator.hpp>
#include "fem_test_utils.hpp"

namespace icd::fem {
namespace {

bool bitwise_equal(const MatX3d& a, const MatX3d& b) {
  return a.rows() == b.rows() && std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0;
}

class ParallelPerModel : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(ParallelPerModel, ForcesEnergyAndDifferentialAreBitwiseIdenticalFor1And2Threads) {
  const TetMeshData d = test::box_data(40, 4, 4);  // 3840 tets: several 512-element chunks
  const MatX3d x = d.rest_positions + 0.003 * test::random_field(d.num_nodes, 11);
  const MatX3d dx = test::random_field(d.num_nodes, 12);
  ElasticForces one(d, test::material(GetParam()));
  ForceOptions two_threads;
  two_threads.num_threads = 2;
  ElasticForces two(d, test::material(GetParam()), two_threads);
  MatX3d f1(d.num_nodes, 3), f2(d.num_nodes, 3), df1(d.num_nodes, 3), df2(d.num_nodes, 3);
  const double e1 = one.compute_with_energy(x, f1);
  const double e2 = two.compute_with_energy(x, f2);
  EXPECT_TRUE(bitwise_equal(f1, f2));
  EXPECT_EQ(std::memcmp(&e1, &e2, sizeof(double)), 0);
  one.differential(x, dx, df1);
  two.differential(x, dx, df2);
  EXPECT_TRUE(bitwise_equal(df1, df2));
  // The results are not trivially zero, and a different input changes them
  // (so the comparison could fail).
  EXPECT_GT(f1.norm(), 0.0);
  MatX3d f3(d.num_nodes, 3);
  two.compute(x + 1e-9 * dx, f3);
  EXPECT_FALSE(bitwise_equal(f1, f3));
}

TEST_P(ParallelPerModel, LaneLoopsAreBitwiseIdenticalForTheBaselineAndAvx2InstructionSets) {
  // Only where the CPU has AVX2 (else there is one build to run).
  if (!lanes::set_lane_isa(lanes::LaneIsa::AVX2)) GTEST_SKIP() << "no AVX2 on this CPU";
  const TetMeshData d =
      test::box_data(9, 2, 1);  // 108 tets: 13 whole 8-lane blocks and a partial one
  const MatX3d x = d.rest_positions + 0.01 * test::random_field(d.num_nodes, 21);
  const MatX3d dx = test::random_field(d.num_nodes, 22);
  MatX3d f[2], df[2];
  ElementHealth h[2];
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(lanes::set_lane_isa(k == 0 ? lanes::LaneIsa::Baseline : lanes::LaneIsa::AVX2));
    ElasticForces forces(d, test::material(GetParam()));
    f[k].resize(d.num_nodes, 3);
    df[k].resize(d.num_nodes, 3);
    h[k] = forces.compute_with_health(x, f[k]);
    forces.differential(x, dx, df[k]);
  }
  EXPECT_TRUE(bitwise_equal(f[0], f[1]));
  EXPECT_TRUE(bitwise_equal(df[0], df[1]));
  EXPECT_EQ(std::memcmp(&h[0].energy, &h[1].energy, sizeof(double)), 0);
  EXPECT_EQ(h[0].min_det_f, h[1].min_det_f);
  EXPECT_EQ(h[0].min_det_f_element, h[1].min_det_f_element);
  EXPECT_GT(f[0].norm(), 0.0);
  EXPECT_GT(h[0].energy, 0.0);
}

INSTANTIATE_TEST_SUITE_P(AllModels, ParallelPerModel, ::testing::ValuesIn(test::all_models()),
                         test::model_name);

TEST(Parallel, SymplecticEulerNodePassIsBitwiseIdenticalForTheBaselineAndAvx2InstructionSets) {
  // The fused node pass (a, v1, x1 and the start state's energies) is
  // compiled for both instruction sets too; fixed nodes, gravity and mass
  // damping on, 3 #V = 135 dofs (not a multiple of 4: the tail pass too).
  if (!lanes::set_lane_isa(lanes::LaneIsa::AVX2)) GTEST_SKIP() << "no AVX2 on this CPU";
  const TetMesh m = test::box(4, 2, 2, {0.4, 0.2, 0.2});
  ModelOptions mo;
  mo.gravity = {0.0, 0.0, -9.81};
  mo.damping = {2.0, 0.0};
  Model model(m.V, m.T, test::material(MaterialModel::StVK, 1e6, 0.3), mo);
  std::vector<int> fixed;
  for (int i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) < 1e-12) fixed.push_back(i);
  model.set_fixed_nodes(fixed);
  ASSERT_NE(3 * model.num_nodes() % 4, 0);
  State in{model.mesh().rest_positions + 1e-3 * test::random_field(model.num_nodes(), 41),
           test::random_field(model.num_nodes(), 42)};
  State out[2];
  StateEnergies e[2];
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(lanes::set_lane_isa(k == 0 ? lanes::LaneIsa::Baseline : lanes::LaneIsa::AVX2));
    ExplicitStepper stepper;
    StepExtras extras;
    extras.energies = &e[k];
    stepper.symplectic_euler(model, in, out[k], 1e-4, extras);
  }
  EXPECT_TRUE(bitwise_equal(out[0].x, out[1].x));
  EXPECT_TRUE(bitwise_equal(out[0].v, out[1].v));
  EXPECT_EQ(std::memcmp(&e[0], &e[1], sizeof(StateEnergies)), 0);
  EXPECT_GT((out[0].v - in.v).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(e[0].kinetic, 0.0);
}

TEST(Parallel, SimulationIsBitwiseIdenticalFor1And2Threads) {
  // Three frames: from the second on, the first step and the estimate reuse
  // the forces of the previous frame's final check; both explicit integrators.
  for (Integrator integ : {Integrator::RK4, Integrator::SymplecticEuler}) {
    MatX3d result[2];
    for (int threads : {1, 2}) {
      SimulatorOptions o;
      o.integrator = integ;
      // 1620 tets: four 512-element chunks.
      Simulator sim(test::cantilever(3, test::material(MaterialModel::Corotational, 1e6, 0.3), 9.81,
                                     {1.0, 1e-4}, threads),
                    o);
      for (int f = 0; f < 3; ++f) sim.advance(1.0 / 240);
      result[threads - 1] = sim.positions();
    }
    EXPECT_TRUE(bitwise_equal(result[0], result[1])) << to_string(integ);
    EXPECT_GT(
        (result[0] -
         test::cantilever(3, test::material(MaterialModel::Corotational)).mesh().rest_positions)
            .cwiseAbs()
            .maxCoeff(),
        0.0);
  }
}

}  // namespace
}  // namespace icd::fem
