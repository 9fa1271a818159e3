#pragma once
/// The simulation object of one deformable body: state, frame advance with
/// automatic sub-stepping below the stable limit, health checks with rollback
/// and bounded retries.
#include <string>
#include <utility>
#include <vector>

#include <icd/fem/backward_euler.hpp>
#include <icd/fem/integrators.hpp>
#include <icd/fem/stable_step.hpp>

namespace icd::fem {

/// Whether an inverted element (det F <= 0) fails the health check.
enum class InversionPolicy {
  Auto,  ///< allowed only for the inversion-safe StableNeoHookean model
  Allow,
  Fail
};

/// How the health checks inside a frame test the energy growth (the last
/// state of every advance()/step() call always takes the full check).
enum class EnergyCheck {
  /// The bound where it is sound, else Full. Sound where the elastic energy
  /// density is >= 0 (Linear, Corotational, StVK: psi >= 0 for any F) and
  /// det F is checked (inversion not allowed), with an explicit integrator.
  Auto,
  /// Kinetic energy + load potential - (total energy of the last full check)
  /// may not exceed the growth allowed (W >= 0 dropped: a necessary
  /// condition of the full check against that state), plus det F > 0 and a
  /// finite state: no energy sum and no smallest det F in the element loop.
  /// A failure rolls back to the last fully checked state (the frame start).
  Bound,
  /// KE + W + load potential against the last check, W summed in the element loop.
  Full
};

/// Options of a Simulator.
struct SimulatorOptions {
  Integrator integrator = Integrator::RK4;
  /// Automatic steps are safety_factor x the stable limit, in (0, 1].
  double safety_factor = 0.9;
  /// > 0: use this step (s); refused with a ParameterError naming the limit if
  /// it exceeds the stable limit of the current state. 0: automatic.
  double fixed_step = 0;
  /// Largest step (s), also the backward Euler step when fixed_step is 0.
  double max_step = 1e-2;
  FrequencyOptions frequency;  ///< includes the added contact stiffness
  /// Lanczos iterations of the per-frame re-estimate once a previous Ritz
  /// vector exists (warm start; the first estimate uses frequency.max_iterations).
  int frequency_refresh_iterations = 5;
  /// Lanczos tolerance (residual / Ritz value) of those warm re-estimates;
  /// the step limit uses FrequencyEstimate::omega_bound, which includes the
  /// residual. Measured on the fem_realtime bar over 3 s against converged
  /// cold-start estimates of every frame's state (fem_frequency_tracking;
  /// experiments/studies/fem/results/README.md):
  /// with frequency.warm_modes = 3, 5 iterations and 1e-3 the estimate is
  /// at most 2.3% low; a single warm vector with 4 iterations was up to 7%
  /// (tolerance 1e-5) or 10% (1e-2) low, as the top mode changes.
  double frequency_refresh_tolerance = 1e-3;
  /// Those warm re-estimates take their products by forward differences of
  /// the forces (FrequencyOptions::finite_difference_products: one force
  /// evaluation each instead of a force differential, relative error ~1e-7).
  bool frequency_refresh_finite_differences = true;
  /// Reuse the last largest-eigenfrequency estimate for calls of advance() /
  /// step() within this much simulated time (s, >= 0; 0 = estimate at every
  /// call). For callers that advance in many short pieces (the runner's
  /// detection/response cycles); the health checks still guard every step.
  double frequency_reuse_time = 0;
  /// A reused estimate is dropped (estimated again) once any edge of the
  /// mesh has changed length by more than this fraction since the estimate
  /// was made (>= 0; infinity: never): a squeezed object stiffens within a frame. Measured
  /// (StableStep.AmortisedEstimateNeverStepsAboveTheTrueLimitOfAnyCycle): an
  /// estimate reused over 10 ms of a hard squeeze without this let symplectic
  /// Euler step 13% above the true limit. A safeguard tested against the dense
  /// eigensolve, not a proven bound.
  double frequency_reuse_strain = 0.01;
  /// More strain allowed before a reused estimate is dropped when the step
  /// that advance() would take with it is below its limit: per unit of slack
  /// s - 1, where s = safety_factor x the estimate's limit / that step (>= 0;
  /// 0: frequency_reuse_strain alone). It holds while omega_max grows by at
  /// most a factor 1 + (strain - frequency_reuse_strain) / this (0.1: 10x the
  /// edge strain; 0.25 let symplectic Euler step 0.4 % above the dense
  /// oracle's limit in StableStep.AmortisedEstimateNeverStepsAboveTheTrueLimitOfAnyCycle,
  /// where part of the slack goes to the estimate's own error). For callers
  /// that advance in pieces shorter than the step (coupling::World's contact
  /// cycles), which would otherwise estimate again at almost every piece of a
  /// vibrating object. A safeguard tested against the dense eigensolve
  /// (StableStep.SlackAllowsMoreStrainButNeverAStepAboveTheTrueLimit), not a
  /// proven bound; the health checks still guard every step.
  double frequency_reuse_strain_per_slack = 0.1;
  /// Sub-steps between health checks (>= 1; default: every step). With the
  /// explicit integrators a check rides on the next step: det F (and, with
  /// EnergyCheck::Full, the elastic energy) of state n in the element pass
  /// of its first force evaluation (at x_n), kinetic energy and load
  /// potential in its first node pass. Cost per simulated second on the
  /// fem_realtime bar (StVK, AVX2 lane loops; experiments/studies/fem/results/
  /// README.md, "fem_realtime: the real-time claim"): the kernel part of
  /// EnergyCheck::Bound (the default here) is 0-2 ns/tet of a ~23 ns/tet
  /// force evaluation, of Full ~3; every step against frame ends only costs
  /// RK4 +2-3% and symplectic Euler +4-7% with Bound (+2% / +7-8% with
  /// Full, +4% / +12% with the code of commit 0a53428). Only the last state of an
  /// advance()/step() call needs a separate element pass, always with the
  /// full check (which also computes the forces there for the next call).
  /// A blow-up is caught at most this many steps late and rolled back to the
  /// last checked state (with EnergyCheck::Bound: the last fully checked one).
  int check_interval = 1;
  /// A check fails when KE + W grows by more than this fraction of
  /// (KE + W + |work of the loads|) since the last check (explicit blow-up).
  double max_energy_growth = 1.0;
  /// Energy test of the checks inside a frame (see EnergyCheck); Bound is
  /// taken as Full where it is not sound.
  EnergyCheck energy_check = EnergyCheck::Auto;
  InversionPolicy inversion = InversionPolicy::Auto;
  int max_retries = 6;   ///< halvings of the step before giving up
  NewtonOptions newton;  ///< backward Euler
};

/// What advance() did.
struct AdvanceReport {
  int substeps = 0;       ///< accepted sub-steps
  int retries = 0;        ///< rollbacks
  double step = 0;        ///< last sub-step used, s
  double step_limit = 0;  ///< stable limit at the start of the frame, s (inf for backward Euler)
  double omega_max =
      0;  ///< largest eigenfrequency bound at the start (FrequencyEstimate::omega_bound), rad/s
  /// Lanczos products spent on that bound in this call (0: reused, see
  /// frequency_reuse_time), rate of the strain-rate damping excluded.
  int frequency_products = 0;
};

/// One object over time. Starts at rest in the rest configuration.
class Simulator {
 public:
  /// Throws ParameterError for invalid options.
  Simulator(Model model, const SimulatorOptions& options = {});

  Model& model() { return m_model; }
  const SimulatorOptions& options() const { return m_options; }
  const State& state() const { return m_state; }
  const MatX3d& positions() const { return m_state.x; }
  const MatX3d& velocities() const { return m_state.v; }
  double time() const { return m_time; }
  /// Sets positions / velocities (#V x 3); ParameterError on shape or non-finite values.
  void set_positions(const Eigen::Ref<const MatX3d>& x);
  /// As set_positions, for a small correction of the current state (e.g. a
  /// static obstacle projecting the surface out): the last stable-step
  /// estimate is kept under the same reuse rules as the motion of the
  /// simulation itself (frequency_reuse_time, and dropped once any edge has
  /// changed length by more than frequency_reuse_strain since it was made),
  /// where set_positions always estimates again. The forces and health of
  /// the new state are computed again as after set_positions.
  void correct_positions(const Eigen::Ref<const MatX3d>& x);
  void set_velocities(const Eigen::Ref<const MatX3d>& v);
  /// Forwards to Model::set_external_forces.
  void set_external_forces(const Eigen::Ref<const MatX3d>& f) { m_model.set_external_forces(f); }

  /// Stable step limit (s) of the configured integrator for the current state
  /// (inf for backward Euler); also updates last_frequency().
  double stable_step_limit() { return stable_step_limit(0); }
  const FrequencyEstimate& last_frequency() const { return m_frequency; }

  /// Advances by frame_dt (s) in equal sub-steps: the fixed step, or
  /// safety_factor x the current limit (capped at max_step). Health checks
  /// every check_interval sub-steps; on failure rolls back to the last good
  /// state, halves the step and retries, at most max_retries times, then
  /// throws NumericalError naming the node/element and quantities.
  AdvanceReport advance(double frame_dt);
  /// One step of exactly dt (s) (sub-divided only by retries). Throws
  /// ParameterError naming the limit if dt exceeds the stable limit.
  AdvanceReport step(double dt);

  /// Total mechanical energy KE + W + load potential of the current state, J.
  double total_energy();

 private:
  struct Check {
    bool ok = true;
    std::string message;
    double kinetic = 0, elastic = 0, load = 0;
  };
  /// Health check of state s with its energies and the element health h of
  /// s.x, against the last accepted check.
  Check evaluate(const Check& before, const State& s, const StateEnergies& energies,
                 const ElementHealth& h) const;
  /// The EnergyCheck::Bound check of state s (energies and the orientation
  /// test of s.x) against the last full check; names the element by a
  /// separate health pass when the orientation test fails.
  Check evaluate_bound(const Check& before, const State& s, const StateEnergies& energies,
                       bool oriented);
  /// Whether the checks inside a frame use EnergyCheck::Bound.
  bool bound_checks() const;
  /// The total-energy growth a step may show over the accepted check before
  /// (max_energy_growth of its energy and of the load potential's change to
  /// `load`, plus the energy floor), J; shared by both checks.
  double allowed_growth(const Check& before, double load) const;
  /// Check failure naming the first node of s with a non-finite x or v
  /// (called when the kinetic energy or the load potential is not finite).
  Check nonfinite_state(const State& s) const;
  /// One step from m_state into m_next; returns an empty string, or why the
  /// step failed (Newton). extras: explicit integrators only.
  std::string integrate(double h, const StepExtras& extras = {});
  AdvanceReport run(double total, double h, AdvanceReport rep);
  void refuse_if_above_limit(double h, double limit, const char* what) const;

  Model m_model;
  SimulatorOptions m_options;
  State m_state;
  State m_next, m_good;  ///< step output and last checked state (run())
  double m_time = 0;
  ExplicitStepper m_explicit;
  BackwardEulerStepper m_implicit;
  FrequencyEstimate m_frequency;
  Eigen::VectorXd m_warm_mode, m_warm_damping;
  double m_damping_rate = 0;  ///< estimate_max_damping_rate() of the last estimate, 1/s
  double m_energy_floor = 0;
  double m_estimate_time = -1;   ///< simulated time of the last frequency estimate (-1: none)
  double m_cached_limit = 0;     ///< stable step limit of that estimate, s
  /// Mesh edges (node pairs) and their lengths at the last estimate (m).
  std::vector<std::pair<int, int>> m_edges;
  Eigen::VectorXd m_estimate_lengths;
  /// stable_step_limit() for advance(frame_dt) (0: no step planned, no slack).
  double stable_step_limit(double frame_dt);
  /// Whether some edge has changed length by more than `tolerance` (a
  /// fraction) since the last estimate.
  bool deformed_since_estimate(double tolerance) const;
  void record_estimate_lengths();
  int m_last_products = 0;       ///< Lanczos products of the last stable_step_limit()
  bool m_checked_valid = false;  ///< m_checked_elastic is the elastic energy of m_state
  double m_checked_elastic = 0;
  /// f_int(m_state.x) from the health check that ended the last run()
  /// (explicit integrators): the next frame's estimate and first step use it
  /// instead of evaluating the forces at the same positions again.
  MatX3d m_end_force;
  bool m_end_force_valid = false;
};

}  // namespace icd::fem
