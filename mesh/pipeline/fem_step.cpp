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
  TetMesh out;
  fem::bcc_block(n, h, out.V, out.T);
  out.F = boundary_faces(out.T);
  return out;
}

namespace {

struct Estimate {
  double omega = 0, step = 0;
  bool converged = false;
  fem::MassScalingReport scaling;
};

Estimate estimate(const MatX3d& V, const MatX4i& T, const StableStepOptions& o,
                  double mass_scaling_target = 0) {
  fem::ModelOptions mo;
  mo.damping = o.damping;
  mo.mass_scaling.target_ratio = mass_scaling_target;
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
  e.scaling = model.mass_scaling();
  return e;
}

}  // namespace

StableStepReport stable_step_report(const TetMesh& mesh, const StableStepOptions& o) {
  fem::validate(o.material);
  if (!(o.damping.alpha >= 0) || !(o.damping.beta >= 0) || o.ideal_cells < 2)
    throw ParameterError(
        "stable_step_report: need Rayleigh coefficients >= 0 and ideal_cells >= 2");
  fem::MassScaling ms;
  ms.target_ratio = o.mass_scaling_target;
  fem::validate(ms);
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
  if (o.mass_scaling_target > 0) {
    const Estimate scaled = estimate(mesh.V, mesh.T, o, o.mass_scaling_target);
    r.scaling = scaled.scaling;
    r.scaled_step = scaled.step;
    r.scaled_ratio = best.step > 0 ? scaled.step / best.step : 0.0;
  }
  return r;
}

std::string StableStepReport::to_string(const StableStepOptions& o) const {
  if (!error.empty()) return "stable step: not computed (" + error + ")";
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "stable step (%s, %s E %.3g Pa nu %.3g rho %.4g, Rayleigh [%g, %g], the mesh "
                "in metres) %.4g s, ideal %.4g s (near-regular tets of the same mean volume): "
                "ratio %.3f%s",
                fem::to_string(o.integrator), fem::to_string(o.material.model), o.material.young,
                o.material.poisson, o.material.density, o.damping.alpha, o.damping.beta, step,
                ideal_step, ratio, converged ? "" : " (Lanczos not converged)");
  std::string out = buf;
  if (scaling.target_ratio > 0) {
    if (scaling.scaled_nodes == 0) {
      std::snprintf(buf, sizeof buf, "; mass scaling to %.2g (the scenes' default): nothing to add",
                    scaling.target_ratio);
    } else {
      std::snprintf(buf, sizeof buf,
                    "; with mass scaling to %.2g (the scenes' default, fem.mass_scaling_target): "
                    "+%.3g %% mass on %d nodes (max x %.3g), step %.4g s, ratio %.3f%s",
                    scaling.target_ratio, 100.0 * scaling.added_fraction, scaling.scaled_nodes,
                    scaling.max_factor, scaled_step, scaled_ratio,
                    scaling.shortfall().c_str());
    }
    out += buf;
  }
  return out;
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
