#include <icd/fem/simulator.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

// Equal sub-steps of at most h that cover `span` (at least one; a span a
// rounding error past a multiple of h takes no extra step): run() steps by
// it, and stable_step_limit() predicts the step advance() will take from it.
int substep_count(double span, double h) {
  return std::max(static_cast<int>(std::ceil(span / h * (1 - 1e-12))), 1);
}

}  // namespace

Simulator::Simulator(Model model, const SimulatorOptions& options)
    : m_model(std::move(model)), m_options(options) {
  auto bad = [](const char* field, double value, const char* range) {
    std::ostringstream os;
    os << "fem::SimulatorOptions." << field << " = " << value << " is invalid: expected " << range;
    throw ParameterError(os.str());
  };
  if (!(options.safety_factor > 0 && options.safety_factor <= 1))
    bad("safety_factor", options.safety_factor, "(0, 1]");
  if (!(options.fixed_step >= 0) || !std::isfinite(options.fixed_step))
    bad("fixed_step", options.fixed_step, ">= 0 s");
  if (!(options.max_step > 0) || !std::isfinite(options.max_step))
    bad("max_step", options.max_step, "> 0 s");
  if (options.frequency_refresh_iterations < 1)
    bad("frequency_refresh_iterations", options.frequency_refresh_iterations, ">= 1");
  if (options.check_interval < 1) bad("check_interval", options.check_interval, ">= 1");
  if (!(options.frequency_refresh_tolerance > 0) || !(options.frequency_refresh_tolerance < 1))
    bad("frequency_refresh_tolerance", options.frequency_refresh_tolerance, "(0, 1)");
  if (!(options.max_energy_growth > 0)) bad("max_energy_growth", options.max_energy_growth, "> 0");
  if (options.max_retries < 0) bad("max_retries", options.max_retries, ">= 0");
  if (!(options.frequency_reuse_time >= 0) || !std::isfinite(options.frequency_reuse_time))
    bad("frequency_reuse_time", options.frequency_reuse_time, ">= 0 s");
  if (!(options.frequency_reuse_strain >= 0))
    bad("frequency_reuse_strain", options.frequency_reuse_strain, ">= 0 (inf: no trigger)");
  if (!(options.frequency_reuse_strain_per_slack >= 0) ||
      !std::isfinite(options.frequency_reuse_strain_per_slack))
    bad("frequency_reuse_strain_per_slack", options.frequency_reuse_strain_per_slack, ">= 0, finite");
  m_state.x = m_model.mesh().rest_positions;
  m_state.v = MatX3d::Zero(m_model.num_nodes(), 3);
  m_energy_floor = 1e-10 * m_model.material().young * m_model.mesh().rest_volume.sum();
}

void Simulator::set_positions(const Eigen::Ref<const MatX3d>& x) {
  if (x.rows() != m_model.num_nodes() || !x.allFinite())
    throw ParameterError("fem::Simulator::set_positions: expected a finite #V x 3 array, #V = " +
                         std::to_string(m_model.num_nodes()));
  m_state.x = x;
  m_estimate_time = -1;  // a new configuration: estimate again
  m_checked_valid = false;
  m_end_force_valid = false;
}

void Simulator::correct_positions(const Eigen::Ref<const MatX3d>& x) {
  const double estimate_time = m_estimate_time;
  set_positions(x);
  // (the estimate's edge lengths stay: deformed_since_estimate() measures
  // the correction together with the motion since the estimate)
  m_estimate_time = estimate_time;
}

void Simulator::set_velocities(const Eigen::Ref<const MatX3d>& v) {
  if (v.rows() != m_model.num_nodes() || !v.allFinite())
    throw ParameterError("fem::Simulator::set_velocities: expected a finite #V x 3 array, #V = " +
                         std::to_string(m_model.num_nodes()));
  m_state.v = v;
  for (int i = 0; i < m_model.num_nodes(); ++i)
    if (m_model.fixed_nodes()[i]) m_state.v.row(i).setZero();
}

double Simulator::stable_step_limit(double frame_dt) {
  if (m_options.integrator == Integrator::BackwardEuler)
    return std::numeric_limits<double>::infinity();
  // Reuse a recent estimate when allowed (see SimulatorOptions::frequency_reuse_time),
  // with more strain when the step advance(frame_dt) would take with it has
  // slack (frequency_reuse_strain_per_slack).
  bool fresh = m_estimate_time >= 0 && m_time - m_estimate_time < m_options.frequency_reuse_time;
  if (fresh) {
    double tolerance = m_options.frequency_reuse_strain;
    if (frame_dt > 0 && m_options.fixed_step == 0 && m_options.frequency_reuse_strain_per_slack > 0 &&
        m_cached_limit > 0 && std::isfinite(m_cached_limit)) {
      const double h = std::min(m_options.max_step, m_options.safety_factor * m_cached_limit);
      const double taken = frame_dt / substep_count(frame_dt, std::min(h, frame_dt));
      const double slack = m_options.safety_factor * m_cached_limit / taken;
      if (slack > 1) tolerance += m_options.frequency_reuse_strain_per_slack * (slack - 1);
    }
    fresh = !deformed_since_estimate(tolerance);
  }
  m_last_products = 0;
  if (fresh) return m_cached_limit;
  FrequencyOptions fo = m_options.frequency;
  if (m_warm_mode.size() == 3 * m_model.num_nodes()) {
    fo.max_iterations = std::min(fo.max_iterations, m_options.frequency_refresh_iterations);
    fo.tolerance = std::max(fo.tolerance, m_options.frequency_refresh_tolerance);
    fo.finite_difference_products =
        fo.finite_difference_products || m_options.frequency_refresh_finite_differences;
  }
  m_frequency = estimate_max_frequency(m_model, m_state.x, fo, &m_warm_mode,
                                       m_end_force_valid ? &m_end_force : nullptr);
  m_last_products = m_frequency.iterations;
  if (m_model.strain_rate_damping().enabled()) {
    FrequencyOptions fd = m_options.frequency;
    if (m_warm_damping.size() == 3 * m_model.num_nodes()) {
      fd.max_iterations = std::min(fd.max_iterations, m_options.frequency_refresh_iterations);
      fd.tolerance = std::max(fd.tolerance, m_options.frequency_refresh_tolerance);
    }
    m_damping_rate = estimate_max_damping_rate(m_model, m_state.x, fd, &m_warm_damping);
  } else {
    m_damping_rate = 0;
  }
  m_estimate_time = m_time;
  if (m_options.frequency_reuse_time > 0) record_estimate_lengths();
  m_cached_limit = m_frequency.omega_bound <= 0  // all fixed
                       ? std::numeric_limits<double>::infinity()
                       : fem::stable_step_limit(m_options.integrator, m_frequency.omega_bound,
                                                m_model.damping(), m_damping_rate);
  return m_cached_limit;
}

void Simulator::record_estimate_lengths() {
  const MatX4i& T = m_model.elastic().mesh().tets;
  if (m_edges.empty() && T.rows() > 0) {
    for (int e = 0; e < T.rows(); ++e)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b)
          m_edges.emplace_back(std::min(T(e, a), T(e, b)), std::max(T(e, a), T(e, b)));
    std::sort(m_edges.begin(), m_edges.end());
    m_edges.erase(std::unique(m_edges.begin(), m_edges.end()), m_edges.end());
  }
  m_estimate_lengths.resize(static_cast<Eigen::Index>(m_edges.size()));
  for (size_t k = 0; k < m_edges.size(); ++k)
    m_estimate_lengths[static_cast<Eigen::Index>(k)] =
        (m_state.x.row(m_edges[k].first) - m_state.x.row(m_edges[k].second)).norm();
}

bool Simulator::deformed_since_estimate(double tol) const {
  if (m_estimate_lengths.size() != static_cast<Eigen::Index>(m_edges.size())) return true;
  for (size_t k = 0; k < m_edges.size(); ++k) {
    const double l0 = m_estimate_lengths[static_cast<Eigen::Index>(k)];
    const double l = (m_state.x.row(m_edges[k].first) - m_state.x.row(m_edges[k].second)).norm();
    if (!(std::abs(l - l0) <= tol * l0)) return true;
  }
  return false;
}

double Simulator::total_energy() {
  return m_model.kinetic_energy(m_state.v) + m_model.elastic().energy(m_state.x) +
         m_model.load_potential(m_state.x);
}

void Simulator::refuse_if_above_limit(double h, double limit, const char* what) const {
  if (h <= limit) return;
  std::ostringstream os;
  os << "fem::Simulator: " << what << " " << h << " s exceeds the stable step limit " << limit
     << " s of " << to_string(m_options.integrator)
     << " for the current state (largest eigenfrequency " << m_frequency.omega_bound
     << " rad/s, Rayleigh alpha " << m_model.damping().alpha << ", beta " << m_model.damping().beta
     << ", strain-rate damping rate up to " << m_damping_rate << " 1/s, contact stiffness "
     << m_options.frequency.contact_stiffness << " N/m); use a step <= " << limit
     << " s or automatic stepping (fixed_step = 0)";
  throw ParameterError(os.str());
}

std::string Simulator::integrate(double h, const StepExtras& extras) {
  switch (m_options.integrator) {
    case Integrator::RK4:
      m_explicit.rk4(m_model, m_state, m_next, h, extras);
      break;
    case Integrator::SymplecticEuler:
      m_explicit.symplectic_euler(m_model, m_state, m_next, h, extras);
      break;
    case Integrator::BackwardEuler: {
      assert(!extras.health && !extras.energies && !extras.elastic);
      m_next = m_state;
      const NewtonReport rep = m_implicit.step(m_model, m_next, h, m_options.newton);
      if (!rep.converged) {
        std::ostringstream os;
        os << "backward Euler Newton did not converge in " << rep.iterations
           << " iterations: residual " << rep.residual << " N s, reference " << rep.reference
           << " N s";
        return os.str();
      }
      break;
    }
  }
  return {};
}

Simulator::Check Simulator::nonfinite_state(const State& s) const {
  Check c;
  c.ok = false;
  const int n = m_model.num_nodes();
  for (int i = 0; i < n; ++i)
    if (!s.x.row(i).allFinite() || !s.v.row(i).allFinite()) {
      std::ostringstream os;
      os << "node " << i << " has a non-finite state: x = (" << s.x.row(i) << "), v = ("
         << s.v.row(i) << ")";
      c.message = os.str();
      return c;
    }
  c.message = "the kinetic energy or the load potential overflows";
  return c;
}

bool Simulator::bound_checks() const {
  if (m_options.integrator == Integrator::BackwardEuler ||
      m_options.energy_check == EnergyCheck::Full)
    return false;
  const MaterialModel mm = m_model.material().model;
  const bool nonnegative_energy =
      mm == MaterialModel::Linear || mm == MaterialModel::Corotational || mm == MaterialModel::StVK;
  return nonnegative_energy &&
         m_options.inversion != InversionPolicy::Allow;  // Auto: inversion checked for these
}

Simulator::Check Simulator::evaluate_bound(const Check& before, const State& s,
                                           const StateEnergies& energies, bool oriented) {
  // Every entry of x and v enters the energy sums (0 * NaN = NaN): finite sums, finite state.
  if (!std::isfinite(energies.kinetic) || !std::isfinite(energies.load)) return nonfinite_state(s);
  Check c;
  c.kinetic = energies.kinetic;
  c.load = energies.load;
  if (!oriented) {
    // Rare (a failing state): the separate health pass names the element.
    const ElementHealth h = m_model.elastic().health(s.x);
    const int e = h.first_nonfinite_element >= 0 ? h.first_nonfinite_element : h.min_det_f_element;
    std::ostringstream os;
    if (e >= 0)
      os << "element " << e << " (nodes " << m_model.mesh().tets.row(e) << ") "
         << (h.first_nonfinite_element >= 0 ? "has a non-finite energy" : "is inverted")
         << ": det F = " << m_model.mesh().deformation_gradient(s.x, e).determinant();
    else
      os << "an element has det F <= 0 or NaN";
    c.ok = false;
    c.message = os.str();
    return c;
  }
  // The elastic energy of s is >= 0 (bound_checks()): KE + load potential
  // alone growing past the allowance fails the full check too.
  const double growth = c.kinetic - (before.kinetic + before.elastic) + (c.load - before.load);
  const double allowed = allowed_growth(before, c.load);
  if (!(growth <= allowed)) {
    std::ostringstream os;
    os << "total energy grew by at least " << growth << " J (allowed " << allowed << " J): kinetic "
       << before.kinetic << " -> " << c.kinetic << " J, elastic " << before.elastic
       << " -> >= 0 J, load potential " << before.load << " -> " << c.load << " J";
    c.ok = false;
    c.message = os.str();
  }
  return c;
}

double Simulator::allowed_growth(const Check& before, double load) const {
  return m_options.max_energy_growth *
             (before.kinetic + before.elastic + std::abs(load - before.load)) +
         m_energy_floor;
}

Simulator::Check Simulator::evaluate(const Check& before, const State& s,
                                     const StateEnergies& energies, const ElementHealth& h) const {
  Check c;
  c.kinetic = energies.kinetic;
  c.load = energies.load;
  // Every entry of x and v enters these sums (0 * NaN = NaN): finite sums, finite state.
  if (!std::isfinite(c.kinetic) || !std::isfinite(c.load)) return nonfinite_state(s);
  const bool allow_inversion = m_options.inversion == InversionPolicy::Allow ||
                               (m_options.inversion == InversionPolicy::Auto &&
                                m_model.material().model == MaterialModel::StableNeoHookean);
  if (h.first_nonfinite_element >= 0 || (!allow_inversion && h.min_det_f <= 0)) {
    const int e = h.first_nonfinite_element >= 0 ? h.first_nonfinite_element : h.min_det_f_element;
    std::ostringstream os;
    os << "element " << e << " (nodes " << m_model.mesh().tets.row(e) << ") "
       << (h.first_nonfinite_element >= 0 ? "has a non-finite energy" : "is inverted")
       << ": det F = " << m_model.mesh().deformation_gradient(s.x, e).determinant();
    c.ok = false;
    c.message = os.str();
    return c;
  }
  c.elastic = h.energy;
  const double growth =
      (c.kinetic + c.elastic) - (before.kinetic + before.elastic) + (c.load - before.load);
  const double allowed = allowed_growth(before, c.load);
  if (!(growth <= allowed)) {
    std::ostringstream os;
    os << "total energy grew by " << growth << " J (allowed " << allowed << " J): kinetic "
       << before.kinetic << " -> " << c.kinetic << " J, elastic " << before.elastic << " -> "
       << c.elastic << " J, load potential " << before.load << " -> " << c.load << " J";
    c.ok = false;
    c.message = os.str();
  }
  return c;
}

namespace {

void swap_states(State& a, State& b) {
  a.x.swap(b.x);
  a.v.swap(b.v);
}

}  // namespace

AdvanceReport Simulator::run(double total, double h, AdvanceReport rep) {
  // Explicit integrators check state n in the passes of step n + 1: element
  // health in the element pass of its first force evaluation (which is at
  // x_n), kinetic energy and load potential in its first node pass; so a
  // check costs no extra pass. The last state of the call is checked by a
  // separate element pass that also computes f_int there, which the next
  // call's estimate and first step use. Buffers rotate: m_good (last checked
  // state), m_state (current), m_next (step output).
  const bool fused = m_options.integrator != Integrator::BackwardEuler;
  // EnergyCheck::Bound: the checks inside the frame compare against the
  // last full check (`before` and m_good stay at that state) and a failure
  // rolls back to it; the full check at the call's end updates both.
  const bool bound = bound_checks();
  m_good = m_state;
  double t_good = 0, t = 0;
  Check before;
  // f_int(m_state.x) from the last call's final check, for the first step.
  const MatX3d* start_force = m_end_force_valid ? &m_end_force : nullptr;
  m_end_force_valid = false;
  if (m_checked_valid) {
    before.elastic = m_checked_elastic;
  } else if (fused) {
    m_end_force.resize(m_model.num_nodes(), 3);
    before.elastic = m_model.elastic().compute_with_health(m_state.x, m_end_force).energy;
    start_force = &m_end_force;
  } else {
    before.elastic = m_model.elastic().energy(m_state.x);
  }
  const StateEnergies start_energies = state_energies(m_model, m_state);
  before.kinetic = start_energies.kinetic;
  before.load = start_energies.load;
  m_checked_valid = false;
  const double h0 = h;
  int since_check = 0, steps = 0, steps_good = 0;
  bool pending = false;  // m_state is a step's result that is due a check
  double hh = h;
  // Rolls back to the last checked state and halves the step, or throws.
  auto reject = [&](const Check& c) {
    if (rep.retries >= m_options.max_retries) {
      std::ostringstream os;
      os << "fem::Simulator: " << to_string(m_options.integrator)
         << " failed the health check after " << rep.retries << " retries at t = " << m_time + t
         << " s (step reduced from " << h0 << " to " << hh << " s): " << c.message;
      m_state = m_good;
      m_time += t_good;
      throw NumericalError(os.str());
    }
    ++rep.retries;
    m_state = m_good;
    t = t_good;
    steps = steps_good;
    h *= 0.5;
    since_check = 0;
    pending = false;
    start_force = nullptr;
  };
  while (true) {
    if (pending && (t >= total || !fused)) {
      pending = false;
      ElementHealth health;
      if (fused) {
        m_end_force.resize(m_model.num_nodes(), 3);
        health = m_model.elastic().compute_with_health(m_state.x, m_end_force);
      } else {
        health = m_model.elastic().health(m_state.x);
      }
      const Check c = evaluate(before, m_state, state_energies(m_model, m_state), health);
      if (!c.ok) {
        reject(c);
        continue;
      }
      before = c;
      if (t >= total) {
        m_end_force_valid = fused;
        break;
      }
      m_good = m_state;
      t_good = t;
      steps_good = steps;
    }
    if (t >= total) break;
    const int remaining = substep_count(total - t, h);
    hh = (total - t) / remaining;
    ElementHealth health;
    StateEnergies energies;
    bool oriented = true;
    const bool check_now = pending;
    StepExtras extras;
    if (check_now) {
      if (bound)
        extras.oriented = &oriented;
      else
        extras.health = &health;
      extras.energies = &energies;
    } else if (start_force) {
      extras.elastic = start_force;  // only at the call's start state, never due a check
    }
    start_force = nullptr;
    const std::string step_failure = integrate(hh, extras);
    if (check_now) {
      pending = false;
      const Check c = bound ? evaluate_bound(before, m_state, energies, oriented)
                            : evaluate(before, m_state, energies, health);
      if (!c.ok) {
        reject(c);  // the step just taken from the bad state is discarded
        continue;
      }
      if (!bound) {
        before = c;
        swap_states(m_good, m_state);
        t_good = t;
        steps_good = steps;
      }
    }
    swap_states(m_state, m_next);
    ++steps;
    t = (remaining <= 1) ? total : t + hh;
    if (!step_failure.empty()) {
      Check c;
      c.ok = false;
      c.message = step_failure;
      reject(c);
      continue;
    }
    if (++since_check >= m_options.check_interval || t >= total) {
      since_check = 0;
      pending = true;
    }
  }
  m_checked_elastic = before.elastic;
  m_checked_valid = true;
  rep.step = h;
  rep.substeps = steps;
  m_time += total;
  return rep;
}

AdvanceReport Simulator::advance(double frame_dt) {
  if (!(frame_dt > 0) || !std::isfinite(frame_dt))
    throw ParameterError("fem::Simulator::advance: frame_dt = " + std::to_string(frame_dt) +
                         " must be > 0");
  AdvanceReport rep;
  rep.step_limit = stable_step_limit(frame_dt);
  rep.omega_max = m_frequency.omega_bound;
  rep.frequency_products = m_last_products;
  double h;
  if (m_options.fixed_step > 0) {
    refuse_if_above_limit(m_options.fixed_step, rep.step_limit, "fixed_step");
    h = m_options.fixed_step;
  } else {
    h = std::min(m_options.max_step, m_options.safety_factor * rep.step_limit);
  }
  return run(frame_dt, std::min(h, frame_dt), rep);
}

AdvanceReport Simulator::step(double dt) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw ParameterError("fem::Simulator::step: dt = " + std::to_string(dt) + " must be > 0");
  AdvanceReport rep;
  rep.step_limit = stable_step_limit();
  rep.omega_max = m_frequency.omega_bound;
  rep.frequency_products = m_last_products;
  refuse_if_above_limit(dt, rep.step_limit, "step dt");
  return run(dt, dt, rep);
}

}  // namespace icd::fem
