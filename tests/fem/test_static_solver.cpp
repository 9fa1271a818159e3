// Static equilibrium (Newton + CHOLMOD) against beam theory: stretched bar
// FL/(EA) and the Timoshenko cantilever, with mesh-convergence trends.
#include <icd/fem/static_solver.hpp>

#include <cmath>

#include <gtest/gtest.h>

#include "fem_test_utils.hpp"

namespace icd::fem {
namespace {

// Bar 1 x 0.1 x 0.1 m clamped at x = 0, end face x = 1 loaded by a uniform
// traction F / A along +x (consistent nodal forces: one third of each face area).
double bar_end_displacement(const Material& mat, double force) {
  const TetMesh m = test::box(10, 2, 2);
  Model model(m.V, m.T, mat);
  std::vector<int> fixed;
  for (int i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) < 1e-12) fixed.push_back(i);
  model.set_fixed_nodes(fixed);
  MatX3d f = MatX3d::Zero(m.V.rows(), 3);
  for (int k = 0; k < m.F.rows(); ++k) {
    bool end = true;
    for (int a = 0; a < 3; ++a) end = end && m.V(m.F(k, a), 0) > 1 - 1e-12;
    if (!end) continue;
    const Eigen::Vector3d p0 = m.V.row(m.F(k, 0)), p1 = m.V.row(m.F(k, 1)), p2 = m.V.row(m.F(k, 2));
    const double area = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    for (int a = 0; a < 3; ++a) f(m.F(k, a), 0) += force / 0.01 * area / 3.0;
  }
  model.set_external_forces(f);
  MatX3d x = m.V;
  StaticSolver solver;
  const NewtonReport rep = solver.solve(model, x);
  EXPECT_TRUE(rep.converged) << "residual " << rep.residual;
  double u = 0;
  int n = 0;
  for (int i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) > 1 - 1e-12) {
      u += x(i, 0) - m.V(i, 0);
      ++n;
    }
  return u / n;
}

TEST(StaticSolver, StretchedBarEndDisplacementIsFLOverEA) {
  const double E = 1e7, A = 0.01, L = 1.0;
  for (MaterialModel model : test::all_models()) {
    // nu = 0: the uniaxial state is exact under the full clamp, and linear tets
    // reproduce it exactly (patch test), so only solver round-off remains.
    // Strain F/(EA) = 1e-4: geometric nonlinearity of the finite-strain models
    // changes the response by O(strain) (StVK: 3/2 strain), hence 1e-3.
    const double force = 1e-4 * E * A;
    const double u = bar_end_displacement(test::material(model, E, 0.0), force);
    const double tol = model == MaterialModel::Linear ? 1e-8 : 1e-3;
    EXPECT_NEAR(u, force * L / (E * A), tol * force * L / (E * A)) << to_string(model);
  }
  // nu = 0.3: the clamp restrains the lateral contraction over a length of the
  // order of the width 0.1 m, so the bar is stiffer by O(nu^2 b / L) ~ 1%; 3% bound.
  const double force = 1e-4 * E * A;
  const double u = bar_end_displacement(test::material(MaterialModel::Linear, E, 0.3), force);
  EXPECT_LT(u, force * L / (E * A));
  EXPECT_GT(u, 0.97 * force * L / (E * A));
}

// Timoshenko tip deflection of a clamped beam under its weight q = rho g A.
double timoshenko(const Material& mat) {
  const double E = mat.young, nu = mat.poisson, G = E / (2 * (1 + nu)), A = 0.01, I = 1e-4 / 12,
               L = 1.0;
  const double q = mat.density * 9.81 * A, kappa = 10 * (1 + nu) / (12 + 11 * nu);
  return q * std::pow(L, 4) / (8 * E * I) + q * L * L / (2 * kappa * G * A);
}

// First bending frequency (Hz) of the discrete model by inverse iteration on
// K u = lambda M u with CHOLMOD (y and z modes are degenerate; the Rayleigh
// quotient converges to their common eigenvalue).
double first_frequency(Model& model) {
  Eigen::SparseMatrix<double> K = model.elastic().stiffness(model.mesh().rest_positions);
  const Eigen::SparseMatrix<double> K0 = K;
  apply_dirichlet(K, model.fixed_dofs());
  CholmodSolver solver;
  EXPECT_TRUE(solver.factorize(K));
  const int n = static_cast<int>(K.rows());
  Eigen::VectorXd m(n), u = Eigen::VectorXd::Ones(n);
  for (int i = 0; i < model.num_nodes(); ++i)
    for (int c = 0; c < 3; ++c) m[3 * i + c] = model.fixed_nodes()[i] ? 0.0 : model.mass()[i];
  double lambda = 0;
  for (int it = 0; it < 60; ++it) {
    u = solver.solve(m.cwiseProduct(u));
    u /= std::sqrt(u.dot(m.cwiseProduct(u)));
    lambda = u.dot(K0 * u);
  }
  return std::sqrt(lambda) / (2 * M_PI);
}

TEST(StaticSolver, CantileverConvergesToTimoshenkoWithTheLockingTrendOfLinearTets) {
  const Material mat = test::material(MaterialModel::Linear, 1e8, 0.3);
  const double delta = timoshenko(mat);
  const double f_beam =
      1.8751 * 1.8751 / (2 * M_PI) * std::sqrt(mat.young * (1e-4 / 12) / (mat.density * 0.01));
  std::vector<double> ratio, freq;
  for (int r : {1, 2, 4, 8}) {  // 60, 480, 3840, 30720 tets
    Model model = test::cantilever(r, mat);
    MatX3d x = model.mesh().rest_positions;
    StaticSolver solver;
    const NewtonReport rep = solver.solve(model, x);
    ASSERT_TRUE(rep.converged);
    ratio.push_back(-test::tip_deflection(model, x) / delta);
    freq.push_back(first_frequency(model) / f_beam);
  }
  // Displacement-based elements are too stiff: the compliance is bounded from
  // below, and linear tets add parasitic shear in bending (locking) that decays
  // like (h/t)^2 (element size h over thickness t): u_h / u = 1 / (1 + C (h/t)^2).
  // So the tip deflection increases monotonically towards the beam value and
  // stays below it (1% allowance for the 3D clamp vs. beam-theory difference).
  for (size_t k = 0; k + 1 < ratio.size(); ++k) EXPECT_LT(ratio[k], ratio[k + 1]);
  EXPECT_LT(ratio.back(), 1.01);
  // Error ratios between successive halvings grow towards the asymptotic 4 of
  // an O(h^2) error: for the model above e_h / e_{h/2} = (4 + C/r^2... ) in
  // (1, 4), increasing with r. Measured 1.57, 2.31, 2.96; require >= 1.4 and increasing.
  std::vector<double> err;
  for (double q : ratio) err.push_back(1 - q);
  for (size_t k = 0; k + 1 < err.size(); ++k) EXPECT_GT(err[k] / err[k + 1], 1.4) << k;
  for (size_t k = 0; k + 2 < err.size(); ++k)
    EXPECT_GT(err[k + 1] / err[k + 2], err[k] / err[k + 1]);
  // Finest mesh (h/t = 1/8): C fitted on the coarser meshes is 3.5..4.4, growing
  // slowly; C <= 6 gives u_h/u >= 0.914. Tolerance: 9% below the beam value.
  EXPECT_GT(ratio.back(), 0.91);
  // Richardson extrapolation with the asymptotic order 2 from the two finest meshes
  // removes the leading error term: within 5% of Timoshenko (measured 2.5%).
  EXPECT_NEAR(ratio[3] + (ratio[3] - ratio[2]) / 3.0, 1.0, 0.05);
  // First bending frequency: too stiff means too high, by about sqrt(u / u_h);
  // decreasing with refinement, finest within 6% above the Euler-Bernoulli value
  // (measured 4.1%; shear and rotary inertia lower the true value by ~0.5%).
  for (size_t k = 0; k + 1 < freq.size(); ++k) EXPECT_GT(freq[k], freq[k + 1]);
  EXPECT_GT(freq.back(), 0.99);
  EXPECT_LT(freq.back(), 1.06);
  // Consistency of statics and dynamics on the finest mesh: f_h / f ~ sqrt(u / u_h) within 2%.
  EXPECT_NEAR(freq.back(), 1.0 / std::sqrt(ratio.back()), 0.02);
}

TEST(StaticSolver, NonlinearMaterialsAgreeWithLinearForSmallLoadsAndConvergeForLarge) {
  // Small deflection (E = 1e9: tip/L ~ 1.5e-3): every model matches the linear
  // solution up to geometric nonlinearity O(deflection/L) -> 1%.
  Material lin = test::material(MaterialModel::Linear, 1e9, 0.3);
  Model ref_model = test::cantilever(2, lin);
  MatX3d x_ref = ref_model.mesh().rest_positions;
  StaticSolver ref_solver;
  ASSERT_TRUE(ref_solver.solve(ref_model, x_ref).converged);
  const double u_lin = test::tip_deflection(ref_model, x_ref);
  for (MaterialModel mm :
       {MaterialModel::Corotational, MaterialModel::StVK, MaterialModel::StableNeoHookean}) {
    Model model = test::cantilever(2, test::material(mm, 1e9, 0.3));
    MatX3d x = model.mesh().rest_positions;
    StaticSolver solver;
    const NewtonReport rep = solver.solve(model, x);
    ASSERT_TRUE(rep.converged) << to_string(mm);
    EXPECT_NEAR(test::tip_deflection(model, x), u_lin, 0.01 * std::abs(u_lin)) << to_string(mm);
    // Large deflection (E = 1e6: linear theory predicts 1.5 L): Newton with line
    // search still converges, and the rotation-invariant models hang below the
    // clamp with a tip that moved back towards x = 0 (x_tip < L).
    Model soft = test::cantilever(2, test::material(mm, 1e6, 0.3));
    MatX3d xs = soft.mesh().rest_positions;
    StaticSolver soft_solver;
    const NewtonReport srep = soft_solver.solve(soft, xs);
    EXPECT_TRUE(srep.converged) << to_string(mm) << " residual " << srep.residual;
    EXPECT_LT(xs.col(0).maxCoeff(), 0.95) << to_string(mm);
  }
}

}  // namespace
}  // namespace icd::fem
