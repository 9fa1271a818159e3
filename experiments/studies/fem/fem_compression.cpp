// How much the largest eigenfrequency grows under 70% uniaxial compression,
// per material, and whether our Lanczos estimate matches a dense reference.
//
// A free 0.3 m cube (3 x 3 x 3 cells, 162 tets, 192 dofs), E = 1e6 Pa, rho =
// 1000, homogeneously deformed with F = diag(a, a, 0.3) (compressed along z):
//  - confined:   a = 1 (no lateral motion, e.g. a tight sleeve);
//  - uniaxial:   a from zero lateral stress P_xx(F) = 0 (free sides,
//                frictionless plates: the homogeneous equilibrium), found by
//                a scan and bisection on the stress of constitutive.hpp;
//  - isochoric:  a = 1/sqrt(0.3) (J = 1, the incompressible limit of "free").
// omega_max of K(x) v = omega^2 M v (K the tangent stiffness of the deformed
// state, M lumped) from a dense generalized eigensolver (the reference) and
// from estimate_max_frequency (Lanczos, cold start); ratios to the rest state.
//
// Usage: fem_compression [output.txt]   (also prints to stdout; the file is
// written whole at the end, atomically: a run stopped midway leaves none)
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include <icd/fem/constitutive.hpp>
#include <icd/fem/stable_step.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/atomic_write.hpp>

namespace {

using namespace icd;
using namespace icd::fem;

// P_xx of F = diag(a, a, c) for the material (R = I for a diagonal F > 0).
double lateral_stress(const Material& mat, double a, double c) {
  const Lame l = lame_parameters(mat);
  const Eigen::Matrix3d F = Eigen::Vector3d(a, a, c).asDiagonal();
  switch (mat.model) {
    case MaterialModel::Linear:
      return LinearLaw{l.mu, l.lambda}.stress(F)(0, 0);
    case MaterialModel::Corotational:
      return CorotationalLaw{l.mu, l.lambda}.stress(F, Eigen::Matrix3d::Identity())(0, 0);
    case MaterialModel::StVK:
      return StVKLaw{l.mu, l.lambda}.stress(F)(0, 0);
    case MaterialModel::StableNeoHookean:
      return StableNeoHookeanLaw{l.mu, l.lambda}.stress(F)(0, 0);
  }
  return 0;
}

// Lateral stretch a in [0.05, 4] with P_xx(diag(a, a, c)) = 0 and P_xx
// increasing there (a stable homogeneous equilibrium); of several, the one
// closest to a = 1. Scan for sign changes, then bisect.
double free_lateral_stretch(const Material& mat, double c) {
  double best = std::nan("");
  const int n = 800;
  for (int i = 0; i < n; ++i) {
    double lo = 0.05 + (4.0 - 0.05) * i / n, hi = 0.05 + (4.0 - 0.05) * (i + 1) / n;
    if (!(lateral_stress(mat, lo, c) < 0 && lateral_stress(mat, hi, c) >= 0)) continue;
    for (int k = 0; k < 200; ++k) {
      const double mid = 0.5 * (lo + hi);
      (lateral_stress(mat, mid, c) < 0 ? lo : hi) = mid;
    }
    const double a = 0.5 * (lo + hi);
    if (std::isnan(best) || std::abs(a - 1) < std::abs(best - 1)) best = a;
  }
  return best;
}

double dense_omega_max(Model& model, const MatX3d& x) {
  const Eigen::MatrixXd K = Eigen::MatrixXd(model.elastic().stiffness(x));
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(K.rows(), K.cols());
  for (int i = 0; i < model.num_nodes(); ++i)
    for (int c = 0; c < 3; ++c) M(3 * i + c, 3 * i + c) = model.mass()[i];
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(K, M, Eigen::EigenvaluesOnly);
  return std::sqrt(es.eigenvalues().maxCoeff());
}

int run(int argc, char** argv) {
  using icd::experiments::Cli;
  std::filesystem::path out_path;
  Cli cli("fem_compression", "  Prints the table; OUTPUT gets a copy.");
  cli.argument("OUTPUT", out_path, "also write the table to this file", false);
  if (const auto status = cli.parse(argc, argv)) return *status;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  if (!out_path.empty()) check_writable(out_path);  // before the work
  std::string table;  // the copy for OUTPUT, written whole at the end
  auto emit = [&](const char* line) {
    std::fputs(line, stdout);
    table += line;
  };
  BoxMeshOptions bo;
  bo.nx = bo.ny = bo.nz = 3;
  bo.size = Eigen::Vector3d(0.3, 0.3, 0.3);
  const TetMesh m = make_box_tet_mesh(bo);
  char line[512];
  std::snprintf(line, sizeof line,
                "free cube 0.3 m, %ld tets, %ld dofs, E = 1e6 Pa, F = diag(a, a, 0.3); omega "
                "ratios compressed/rest "
                "by a dense generalized eigensolver (reference) and Lanczos (ours, cold start)\n",
                static_cast<long>(m.T.rows()), static_cast<long>(3 * m.V.rows()));
  emit(line);
  std::snprintf(line, sizeof line, "%-19s %5s %-10s %7s %10s %10s %10s %13s %13s\n", "material",
                "nu", "case", "a", "dense", "Lanczos", "bound", "Lanczos/dense", "bound/dense");
  emit(line);
  const MaterialModel models[4] = {MaterialModel::Linear, MaterialModel::Corotational,
                                   MaterialModel::StVK, MaterialModel::StableNeoHookean};
  double worst = 0;
  for (MaterialModel mm : models)
    for (double nu : {0.3, 0.45, 0.49}) {
      Material mat;
      mat.model = mm;
      mat.young = 1e6;
      mat.poisson = nu;
      Model model(m.V, m.T, mat);
      const double rest_dense = dense_omega_max(model, m.V);
      const double rest_lanczos = estimate_max_frequency(model, m.V, {}).omega_max;
      const char* names[3] = {"confined", "uniaxial", "isochoric"};
      const double stretch[3] = {1.0, free_lateral_stretch(mat, 0.3), 1.0 / std::sqrt(0.3)};
      for (int k = 0; k < 3; ++k) {
        MatX3d x = m.V;
        x.col(0) *= stretch[k];
        x.col(1) *= stretch[k];
        x.col(2) *= 0.3;
        const double dense = dense_omega_max(model, x);
        const FrequencyEstimate est = estimate_max_frequency(model, x, {});
        const double diff = est.omega_max / dense - 1;
        worst = std::max(worst, std::abs(diff));
        std::snprintf(line, sizeof line,
                      "%-19s %5.2f %-10s %7.4f %9.3fx %9.3fx %9.3fx %+13.1e %+13.1e%s\n",
                      to_string(mm), nu, names[k], stretch[k], dense / rest_dense,
                      est.omega_max / rest_lanczos, est.omega_bound / rest_lanczos, diff,
                      est.omega_bound / dense - 1,
                      est.converged ? "" : " (60 iterations, not converged to 1e-5)");
        emit(line);
      }
    }
  std::snprintf(line, sizeof line,
                "largest |Lanczos / dense - 1| over all compressed states: %.1e\n", worst);
  emit(line);
  if (!out_path.empty()) write_file_atomically(out_path, table);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("fem_compression", run, argc, argv);
}
