#include <icd/mesh/pipeline/fem_step.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>
#include <vector>

#include <icd/fem/stable_step.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::mesh {

TetMesh bcc_block(int n, double h) {
  if (n < 2 || !(h > 0.0) || !std::isfinite(h))
    throw ParameterError("bcc_block: need n >= 2 cells and a finite edge h > 0 (got n = " +
                         std::to_string(n) + ", h = " + std::to_string(h) + ")");
  std::map<std::array<int, 3>, int> id;  // doubled integer coordinates -> node
  std::vector<Eigen::RowVector3d> pts;
  const auto node = [&](int x, int y, int z) {
    auto [it, inserted] = id.try_emplace({x, y, z}, static_cast<int>(pts.size()));
    if (inserted) pts.emplace_back(0.5 * h * x, 0.5 * h * y, 0.5 * h * z);
    return it->second;
  };
  std::vector<std::array<int, 4>> tets;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int i = 0; i + 1 < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          // Centres of cells (i, j, k) and (i + 1, j, k) along `axis`, doubled.
          std::array<int, 3> c1{}, c2{};
          c1[axis] = 2 * i + 1, c2[axis] = 2 * i + 3;
          c1[u] = c2[u] = 2 * j + 1;
          c1[v] = c2[v] = 2 * k + 1;
          // Corners of the face between them, in order around it.
          std::array<std::array<int, 3>, 4> q{};
          static constexpr int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
          for (int m = 0; m < 4; ++m) {
            q[m][axis] = 2 * i + 2;
            q[m][u] = 2 * (j + du[m]);
            q[m][v] = 2 * (k + dv[m]);
          }
          const int a = node(c1[0], c1[1], c1[2]), b = node(c2[0], c2[1], c2[2]);
          for (int m = 0; m < 4; ++m) {
            const auto &p = q[m], &r = q[(m + 1) % 4];
            tets.push_back({a, b, node(p[0], p[1], p[2]), node(r[0], r[1], r[2])});
          }
        }
  }
  TetMesh out;
  out.V.resize(static_cast<Eigen::Index>(pts.size()), 3);
  for (size_t i = 0; i < pts.size(); ++i) out.V.row(static_cast<Eigen::Index>(i)) = pts[i];
  out.T.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (size_t t = 0; t < tets.size(); ++t) {
    auto e = tets[t];
    const Eigen::Vector3d p0 = out.V.row(e[0]), p1 = out.V.row(e[1]), p2 = out.V.row(e[2]),
                          p3 = out.V.row(e[3]);
    if ((p1 - p0).dot((p2 - p0).cross(p3 - p0)) < 0) std::swap(e[2], e[3]);
    for (int c = 0; c < 4; ++c) out.T(static_cast<Eigen::Index>(t), c) = e[c];
  }
  out.F = boundary_faces(out.T);
  return out;
}

namespace {

struct Estimate {
  double omega = 0, step = 0;
  bool converged = false;
};

Estimate estimate(const MatX3d& V, const MatX4i& T, const StableStepOptions& o) {
  fem::ModelOptions mo;
  mo.damping = o.damping;
  fem::Model model(V, T, o.material, mo);
  // The Simulator's first estimate (60 iterations) converges on structured
  // meshes; graded Mesh_3 meshes need more for a converged figure.
  fem::FrequencyOptions fo;
  fo.max_iterations = 400;
  const fem::FrequencyEstimate f = fem::estimate_max_frequency(model, V, fo);
  Estimate e;
  e.omega = f.omega_bound;
  e.converged = f.converged;
  e.step = fem::stable_step_limit(o.integrator, f.omega_bound, o.damping);
  return e;
}

}  // namespace

StableStepReport stable_step_report(const TetMesh& mesh, const StableStepOptions& o) {
  fem::validate(o.material);
  if (!(o.damping.alpha >= 0) || !(o.damping.beta >= 0) || o.ideal_cells < 2)
    throw ParameterError(
        "stable_step_report: need Rayleigh coefficients >= 0 and ideal_cells >= 2");
  StableStepReport r;
  if (mesh.T.rows() == 0) {
    r.error = "no tets";
    return r;
  }
  Estimate mine;
  try {
    mine = estimate(mesh.V, mesh.T, o);
  } catch (const InputError& e) {
    r.error = e.what();
    return r;
  }
  r.mean_volume = signed_tet_volumes(mesh.V, mesh.T).mean();
  const TetMesh ideal = bcc_block(o.ideal_cells, std::cbrt(12.0 * r.mean_volume));
  const Estimate best = estimate(ideal.V, ideal.T, o);
  r.omega_max = mine.omega;
  r.ideal_omega_max = best.omega;
  r.step = mine.step;
  r.ideal_step = best.step;
  r.ratio = best.step > 0 ? mine.step / best.step : 0.0;
  r.converged = mine.converged && best.converged;
  return r;
}

std::string StableStepReport::to_string(const StableStepOptions& o) const {
  if (!error.empty()) return "stable step: not computed (" + error + ")";
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "stable step (%s, %s E %.3g Pa nu %.3g rho %.4g, Rayleigh [%g, %g], the mesh "
                "in metres) %.4g s, ideal %.4g s (near-regular tets of the same mean volume): "
                "ratio %.3f%s",
                fem::to_string(o.integrator), fem::to_string(o.material.model), o.material.young,
                o.material.poisson, o.material.density, o.damping.alpha, o.damping.beta, step,
                ideal_step, ratio, converged ? "" : " (Lanczos not converged)");
  return buf;
}

std::string fem_quality_warnings(const StableStepReport& r, double min_dihedral_deg) {
  std::string w;
  char buf[256];
  if (r.error.empty() && r.ratio < kStableStepRatioTarget) {
    std::snprintf(buf, sizeof buf,
                  "the stable step is %.2f x that of near-regular tets (target >= %.1f): the "
                  "worst tets slow the explicit FEM by %.1fx. ",
                  r.ratio, kStableStepRatioTarget, 1.0 / r.ratio);
    w += buf;
  }
  if (min_dihedral_deg < kMinDihedralTargetDeg) {
    std::snprintf(buf, sizeof buf, "the smallest dihedral angle is %.1f deg (target >= %.0f). ",
                  min_dihedral_deg, kMinDihedralTargetDeg);
    w += buf;
  }
  if (!w.empty()) w.pop_back();
  return w;
}

}  // namespace icd::mesh
