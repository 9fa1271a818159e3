#pragma once
/// Stable time step of the explicit integrators from the largest
/// eigenfrequency of the *current* state (it grows under compression).
#include <Eigen/Core>

#include <icd/fem/integrators.hpp>

namespace icd::fem {

/// Options of the largest-eigenfrequency estimate.
struct FrequencyOptions {
  int max_iterations = 60;  ///< Lanczos iterations (>= 1)
  double tolerance = 1e-5;  ///< stop when the Ritz residual <= tolerance * Ritz value
  /// Extra stiffness per node dof (N/m) that contact adds on top of K(x); the
  /// coupling layer sets it to its penalty stiffness. >= 0.
  double contact_stiffness = 0;
  /// The warm start vector returned is the sum of this many top Ritz vectors,
  /// so that a re-estimate also sees the modes just below the top one: the
  /// top mode of a deforming object changes, and a warm start from the old
  /// top vector alone can converge to it after it is no longer the largest
  /// (measured on the fem_realtime bar: up to 10% too low with 1 vector).
  int warm_modes = 3;
  /// Products K u by forward differences of the elastic forces,
  /// K u ~ -(f(x + eps u) - f(x)) / eps, with eps such that the largest nodal
  /// displacement eps |u_i| is 1e-7 of the mean element size: one force
  /// evaluation per product (plus f(x) once) instead of a force differential,
  /// ~2x cheaper with the lane kernels and ~3x for corotational. Relative
  /// error of a product ~1e-7 (the truncation of the strain increment; the
  /// rounding of f is ~1e-8 of it), far below the tolerances of the
  /// Simulator's warm re-estimates, which use it. The Ritz value is then no
  /// longer a strict lower bound of the operator's eigenvalue (by ~1e-7).
  bool finite_difference_products = false;
};

/// Result of estimate_max_frequency().
struct FrequencyEstimate {
  double omega_max = 0;  ///< largest circular eigenfrequency sqrt(lambda_max(M^-1 K)), rad/s
  int iterations = 0;    ///< Lanczos iterations used
  bool converged = false;
  double residual = 0;  ///< Ritz residual / Ritz value at exit
  /// sqrt(theta + |r|) = omega_max sqrt(1 + residual), rad/s: the Ritz value
  /// theta is a lower bound of lambda_max and some eigenvalue lies within the
  /// residual norm |r| of it, so this bounds omega_max from above once the
  /// Ritz pair is the top one. The Simulator's step limits use it.
  double omega_bound = 0;
};

/// Largest eigenvalue of the generalized problem (K(x) + k_c I) u = omega^2 M u
/// on the free dofs, by Lanczos with full reorthogonalisation on
/// M^-1/2 (K + k_c I) M^-1/2, matrix-free (ElasticForces::differential).
/// Why Lanczos rather than a per-element bound: the element eigenvalue bound
/// max_e lambda(K_e, M_e) is a guaranteed upper bound but is ~2x pessimistic
/// on structured tets, and power iteration converges slowly on the clustered
/// top of the spectrum; Lanczos' top Ritz value converges to lambda_max within
/// ~1e-5 in tens of products, and is warm-started from the last Ritz vector
/// (`warm`: in/out, 3#V scaled-space vector; empty = fixed-seed random start).
/// forces_at_x (optional): f_int(x) (#V x 3, N) already computed, used as the
/// base point of the forward-difference products instead of evaluating it.
FrequencyEstimate estimate_max_frequency(Model& model, const Eigen::Ref<const MatX3d>& x,
                                         const FrequencyOptions& options,
                                         Eigen::VectorXd* warm = nullptr,
                                         const MatX3d* forces_at_x = nullptr);

/// Largest stable step (s) of an integrator for modes with circular frequency
/// up to omega_max and Rayleigh damping c(omega) = alpha + beta omega^2
/// (modal damping ratio xi = c / (2 omega)). Per mode:
///  - symplectic Euler: h <= (sqrt(c^2 + 4 omega^2) - c) / omega^2 and h c <= 2
///    (Jury conditions of its 2x2 amplification matrix; 2/omega undamped);
///  - RK4: largest h with |R(h s)| <= 1 for both roots s of s^2 + c s + omega^2,
///    R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 (2 sqrt 2 / omega undamped);
///  - backward Euler: unbounded (returns +infinity).
/// The minimum is taken over omega in (0, omega_max] (log grid), since damping
/// can make a lower mode the limiting one. max_damping_rate (1/s, >= 0): the
/// largest modal rate of the strain-rate damping (estimate_max_damping_rate);
/// its modes need not be the elastic ones, so every mode is also taken with
/// any extra damping in [0, max_damping_rate] (9 levels): conservative.
double stable_step_limit(Integrator integrator, double omega_max, const RayleighDamping& damping,
                         double max_damping_rate = 0);

/// Largest eigenvalue c_max (1/s) of M^-1 D(x) on the free dofs, D = -df_d/dv
/// the (symmetric, positive semi-definite) matrix of the strain-rate damping
/// forces at positions x: the largest modal damping rate. Lanczos as in
/// estimate_max_frequency (options.contact_stiffness unused); returns the
/// residual upper bound theta (1 + residual). 0 when the damping is off.
double estimate_max_damping_rate(Model& model, const Eigen::Ref<const MatX3d>& x,
                                 const FrequencyOptions& options, Eigen::VectorXd* warm = nullptr);

}  // namespace icd::fem
