#pragma once
/// Selective mass scaling (issue 30 item 5, issue 32): in explicit FEM the
/// stable step is set by the largest eigenfrequency of M^-1 K, and on Mesh_3
/// meshes that is a few light surface nodes of thin parts (the dragon's worst
/// has 0.3 % of a mean node's mass). Adding lumped mass to those nodes only,
/// just enough that their own frequency reaches a target, lifts the step of
/// the whole object at the price of a small, measured, change of its inertia
/// (fem/README.md, "Mass scaling").
#include <string>

#include <Eigen/Core>

#include <icd/fem/material.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::fem {

class Model;

/// The default target_ratio of a World's deformable objects
/// (coupling::ObjectSetup, scene files) and of the preprocess summary's
/// figure: why 0.4, fem/README.md "Mass scaling".
inline constexpr double kSceneMassScalingTarget = 0.4;

/// Options of the scaling (ModelOptions::mass_scaling).
struct MassScaling {
  /// Target stable-step ratio against near-regular tets of the same mean
  /// volume and material (ideal_max_frequency): after scaling, the model's
  /// largest eigenfrequency at rest is at most ideal / target_ratio. 0: off
  /// (the lumped masses unchanged); else in (0, 1].
  double target_ratio = 0;
  /// The scaling stops (target not reached, reported) rather than add more
  /// than this fraction of the object's mass, in (0, 1].
  double max_added_fraction = 0.05;
  /// Lanczos-checked passes at most (each lowers the node threshold towards
  /// the target); the scaling stops earlier when the target is reached or
  /// the next pass would exceed max_added_fraction. >= 1.
  int max_passes = 32;
};

/// What the scaling did (Model::mass_scaling()). Frequencies are Lanczos
/// upper bounds (FrequencyEstimate::omega_bound) at the rest state with every
/// node free; ratios are ideal / omega (the undamped step ratio).
struct MassScalingReport {
  double target_ratio = 0;   ///< the option (0: off, nothing else set)
  double ideal_omega = 0;    ///< rad/s, ideal_max_frequency()
  double omega_before = 0;   ///< rad/s, lumped masses
  double omega_after = 0;    ///< rad/s, scaled masses (= omega_before when nothing was added)
  double ratio_before = 0;   ///< ideal_omega / omega_before
  double ratio_after = 0;    ///< ideal_omega / omega_after
  /// Node-frequency threshold of the last pass, rad/s: every node whose own
  /// frequency sqrt(lambda_max(K_ii) / m_i) exceeds it got m_i = lambda_max(K_ii) /
  /// threshold^2; every other node kept its lumped mass exactly.
  double node_omega = 0;
  int scaled_nodes = 0;       ///< nodes whose mass grew
  double added_mass = 0;      ///< kg, in all
  double added_fraction = 0;  ///< added_mass / the object's lumped mass
  double max_factor = 1;      ///< largest scaled / lumped node mass
  int estimates = 0;          ///< Lanczos estimates spent (passes + the first)
  bool reached = false;       ///< ratio_after >= target_ratio
  int passes = 0;             ///< passes run (each one Lanczos estimate)
  /// Why the scaling stopped short of the target (both false when reached):
  /// the next pass would have added more than max_added_fraction ...
  bool mass_limited = false;
  bool pass_limited = false;  ///< ... or max_passes ran out first
  /// One line for summaries, e.g. "mass scaling to 0.4: +1.32 % mass on 138
  /// nodes (max x 8.2), step ratio 0.197 -> 0.400".
  std::string to_string() const;
  /// Empty when reached, else " (target not reached: <why>)": the pass
  /// limit, the added-mass limit, or the first pass already beyond it.
  std::string shortfall() const;
};

/// The near-regular reference mesh: a cube of n x n x n cells of edge h cut
/// into the body-centred cubic lattice's tets (4 per pair of neighbouring
/// cell centres; dihedral angles 60 and 90 deg), 12 n^3 - 12 n^2 positive
/// tets of volume h^3 / 12. Throws ParameterError for n < 2 or h <= 0.
void bcc_block(int n, double h, MatX3d& V, MatX4i& T);

/// Largest eigenfrequency (rad/s, Lanczos upper bound, 400 iterations) at rest
/// of the free 5 x 5 x 5-cell BCC block (1,200 tets) of the material with
/// mean tet volume `mean_volume` (m^3): the "ideal" of the stable-step ratios
/// (mesh/pipeline/fem_step.hpp). At rest every material model is linear
/// elasticity with its (E, nu), and omega scales exactly as sqrt(E / rho) /
/// mean_volume^(1/3): computed once per (model, nu) and scaled (thread-safe).
double ideal_max_frequency(const Material& material, double mean_volume);

/// Per node, lambda_max of the 3x3 diagonal block K_ii of the tangent
/// stiffness at x (#V, N/m): the node frequency is sqrt(this / m_i).
Eigen::VectorXd node_stiffness(Model& model, const Eigen::Ref<const MatX3d>& x);

/// The scaling itself (the Model constructor calls it with its rest state):
/// nodes whose own frequency exceeds a threshold get m_i = lambda_max(K_ii) /
/// threshold^2, starting from the threshold ideal / target_ratio and lowered
/// by the ratio of the Lanczos estimate to the target (raised to the power
/// 1 / the top frequency's measured sensitivity to the threshold, from the
/// last two passes) until the estimate of the scaled model is within the
/// target (coupled light nodes share modes above their own frequencies), the
/// next pass would exceed the added-mass limit, or max_passes ran out (the
/// report says which). Sets the model's masses
/// (Model::set_masses) and returns what it did. Throws ParameterError for bad options.
MassScalingReport apply_mass_scaling(Model& model, const Eigen::Ref<const MatX3d>& rest,
                                     const MassScaling& options);

/// Throws ParameterError naming the field for a bad MassScaling.
void validate(const MassScaling& options);

}  // namespace icd::fem
