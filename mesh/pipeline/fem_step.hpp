#pragma once
/// Tets fit for explicit FEM (issue 30, item 5): the stable step of a coarse
/// tet mesh, computed exactly as the FEM module computes it (fem::Model with
/// lumped mass, Lanczos estimate of the largest eigenfrequency at rest,
/// FrequencyEstimate::omega_bound, fem::stable_step_limit), against an ideal:
/// the same computation on a block of near-regular tets of the same mean
/// volume and material. In explicit FEM the worst element sets the step of
/// the whole object, so the ratio is the frame-rate cost of the tet shapes.
#include <string>

#include <icd/fem/integrators.hpp>
#include <icd/fem/material.hpp>
#include <icd/fem/model.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Material, damping and integrator of the estimate. The defaults are a
/// scene object's defaults (experiments/runner/scene.cpp: fem::Material{},
/// no damping, RK4); the ratio does not depend on Young's modulus or density
/// (without damping both steps scale with sqrt(rho / E)).
struct StableStepOptions {
  fem::Material material;
  fem::RayleighDamping damping;
  fem::Integrator integrator = fem::Integrator::RK4;
  /// Cells per side of the ideal block (bcc_block): 5 gives 1,200 tets, the
  /// ideal within 1 % of larger blocks (StableStepReport measured; the top
  /// mode of a free BCC block lies inside it, not at its boundary).
  int ideal_cells = 5;
  /// Also report the step with selective mass scaling to this ratio
  /// (fem::MassScaling; the scenes' default), 0: not.
  double mass_scaling_target = fem::kSceneMassScalingTarget;
};

/// Result of stable_step_report(). Steps in seconds, the mesh's units taken
/// as metres; the ratio has no unit and no dependence on the scale.
struct StableStepReport {
  double step = 0;        ///< stable limit of the mesh at rest (before the Simulator's safety factor)
  double ideal_step = 0;  ///< the same for the ideal block of the same mean tet volume
  double ratio = 0;       ///< step / ideal_step (1: as good as near-regular tets)
  double omega_max = 0, ideal_omega_max = 0;  ///< omega_bound of each estimate, rad/s
  double mean_volume = 0;                     ///< mean tet volume of the mesh
  bool converged = false;                     ///< both Lanczos estimates converged
  /// With StableStepOptions::mass_scaling_target > 0: what the scaling adds
  /// (fem::apply_mass_scaling) and the step and ratio of the scaled model
  /// (the ratio against this report's ideal; 0 when not computed).
  fem::MassScalingReport scaling;
  double scaled_step = 0, scaled_ratio = 0;
  std::string error;  ///< non-empty when the FEM model refused the mesh (then all figures 0)

  /// One line for the tool's summary.
  std::string to_string(const StableStepOptions& options) const;
};

/// fem::bcc_block with its boundary faces: a cube of n x n x n cells of edge h cut into the body-centred cubic (BCC)
/// lattice's tets: for every pair of neighbouring cell centres, four tets
/// (the two centres and an edge of the face between them); faces on the
/// block's boundary get no tets, so the block is a solid of 12 n^3 - 12 n^2
/// tets of volume h^3 / 12 each. Regular tets cannot fill space; these are
/// the closest space-filling ones (Sommerville's: dihedral angles 60 and 90
/// deg, radius-edge ratio 0.79 against 0.61 for the regular tet), the usual
/// reference of a well-shaped simulation mesh. Throws ParameterError for
/// n < 2 or h <= 0.
TetMesh bcc_block(int n, double h);

/// The stable step of `mesh` (positive tets) and of the ideal block (bcc_block
/// with options.ideal_cells cells, scaled to mesh's mean tet volume), both by
/// fem::estimate_max_frequency at the rest state with default
/// FrequencyOptions and fem::stable_step_limit. Never throws on a bad mesh:
/// a mesh the FEM model refuses (a degenerate tet) gives an error text.
/// Throws ParameterError for a bad material or damping.
StableStepReport stable_step_report(const TetMesh& mesh, const StableStepOptions& options = {});

/// Warnings of the explicit-FEM quality targets (issue 30): the stable-step
/// ratio below 0.4 and the smallest dihedral angle below 12 deg. Empty when
/// both are met; else one sentence per miss, naming the figure and target.
std::string fem_quality_warnings(const StableStepReport& report, double min_dihedral_deg);

/// The targets themselves.
inline constexpr double kStableStepRatioTarget = 0.4;
inline constexpr double kMinDihedralTargetDeg = 12.0;

}  // namespace icd::mesh
