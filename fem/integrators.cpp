#include "fem/integrators.hpp"

#include <cassert>
#include <utility>

namespace icd::fem {

const char* to_string(Integrator integrator) {
  switch (integrator) {
    case Integrator::RK4: return "rk4";
    case Integrator::SymplecticEuler: return "symplectic_euler";
    case Integrator::BackwardEuler: return "backward_euler";
  }
  return "unknown";
}

void ExplicitStepper::resize(int n) {
  if (m_a.rows() == n) return;
  m_a.resize(n, 3);
  m_x.resize(n, 3);
  m_v.resize(n, 3);
  m_dx.resize(n, 3);
  m_dv.resize(n, 3);
}

namespace {

void fit(State& s, long n) {
  if (s.x.rows() != n) s.x.resize(n, 3);
  if (s.v.rows() != n) s.v.resize(n, 3);
}

}  // namespace

StateEnergies state_energies(const Model& model, const State& s) {
  const int n = model.num_nodes();
  assert(s.x.rows() == n && s.v.rows() == n);
  const double* m = model.mass().data();
  const double* load = model.loads().data();
  const double* x = s.x.data();
  const double* v = s.v.data();
  double kinetic = 0, work = 0;
  for (int i = 0; i < n; ++i) {
    const double* vi = v + 3L * i;
    kinetic += m[i] * (vi[0] * vi[0] + vi[1] * vi[1] + vi[2] * vi[2]);
    for (int c = 0; c < 3; ++c) work += load[3L * i + c] * x[3L * i + c];
  }
  return {0.5 * kinetic, -work};
}

void ExplicitStepper::symplectic_euler(Model& model, State& s, double h) {
  symplectic_euler(model, s, m_out, h);
  s.x.swap(m_out.x);
  s.v.swap(m_out.v);
}

void ExplicitStepper::symplectic_euler(Model& model, const State& in, State& out, double h,
                                       ElementHealth* start_health) {
  StepExtras extras;
  extras.health = start_health;
  symplectic_euler(model, in, out, h, extras);
}

namespace {

// The node pass of a symplectic Euler step (see ExplicitStepper::symplectic_euler);
// kEnergies: also the StateEnergies of (x, v), summed as in state_energies().
template <bool kEnergies>
StateEnergies symplectic_euler_nodes(const Model& model, const double* x, const double* v, const double* f,
                                     double h, double* x1, double* v1) {
  const int n = model.num_nodes();
  const double alpha = model.damping().alpha;
  const double* mass = model.mass().data();
  const double* w = model.inverse_mass().data();
  const double* load = model.loads().data();
  const char* fixed = model.fixed_nodes().data();
  double kinetic = 0, work = 0;
  for (int i = 0; i < n; ++i) {
    const double m = mass[i], wi = w[i];
    const bool is_free = !fixed[i];
    const long k = 3L * i;
    if constexpr (kEnergies) {
      kinetic += m * (v[k] * v[k] + v[k + 1] * v[k + 1] + v[k + 2] * v[k + 2]);
      for (int c = 0; c < 3; ++c) work += load[k + c] * x[k + c];
    }
    for (int c = 0; c < 3; ++c) {
      // Exactly zero at fixed nodes, even where the elastic force is not finite.
      const double a = is_free ? wi * (f[k + c] + load[k + c] - m * alpha * v[k + c]) : 0.0;
      v1[k + c] = v[k + c] + h * a;
      x1[k + c] = x[k + c] + h * v1[k + c];
    }
  }
  return {0.5 * kinetic, -work};
}

}  // namespace

void ExplicitStepper::symplectic_euler(Model& model, const State& in, State& out, double h,
                                       const StepExtras& extras) {
  assert(&in != &out);
  const int n = model.num_nodes();
  resize(n);
  fit(out, n);
  model.element_forces(in.x, in.v, m_a, extras.health, extras.elastic);
  if (extras.energies)
    *extras.energies =
        symplectic_euler_nodes<true>(model, in.x.data(), in.v.data(), m_a.data(), h, out.x.data(), out.v.data());
  else
    symplectic_euler_nodes<false>(model, in.x.data(), in.v.data(), m_a.data(), h, out.x.data(), out.v.data());
}

void ExplicitStepper::rk4(Model& model, State& s, double h) {
  rk4(model, s, m_out, h);
  s.x.swap(m_out.x);
  s.v.swap(m_out.v);
}

void ExplicitStepper::rk4(Model& model, const State& in, State& out, double h, ElementHealth* start_health) {
  StepExtras extras;
  extras.health = start_health;
  rk4(model, in, out, h, extras);
}

void ExplicitStepper::rk4(Model& model, const State& in, State& out, double h, const StepExtras& extras) {
  assert(&in != &out);
  const int n = model.num_nodes();
  resize(n);
  fit(out, n);
  const long m = 3L * n;
  const double* x = in.x.data();
  const double* v = in.v.data();
  const double* a = m_a.data();
  double *X = m_x.data(), *V = m_v.data(), *dx = m_dx.data(), *dv = m_dv.data();
  const double hh = 0.5 * h;
  // k1 at y; stage point y + h/2 k1.
  model.acceleration(in.x, in.v, m_a, extras.health, extras.elastic);
  if (extras.energies) *extras.energies = state_energies(model, in);
  for (long k = 0; k < m; ++k) {
    dx[k] = v[k];
    dv[k] = a[k];
    X[k] = x[k] + hh * v[k];
    V[k] = v[k] + hh * a[k];
  }
  // k2 at y + h/2 k1; stage point y + h/2 k2.
  model.acceleration(m_x, m_v, m_a);
  for (long k = 0; k < m; ++k) {
    dx[k] += 2.0 * V[k];
    dv[k] += 2.0 * a[k];
    X[k] = x[k] + hh * V[k];
    V[k] = v[k] + hh * a[k];
  }
  // k3 at y + h/2 k2; stage point y + h k3.
  model.acceleration(m_x, m_v, m_a);
  for (long k = 0; k < m; ++k) {
    dx[k] += 2.0 * V[k];
    dv[k] += 2.0 * a[k];
    X[k] = x[k] + h * V[k];
    V[k] = v[k] + h * a[k];
  }
  // k4 at y + h k3.
  model.acceleration(m_x, m_v, m_a);
  const double h6 = h / 6.0;
  double* x1 = out.x.data();
  double* v1 = out.v.data();
  for (long k = 0; k < m; ++k) {
    x1[k] = x[k] + h6 * (dx[k] + V[k]);
    v1[k] = v[k] + h6 * (dv[k] + a[k]);
  }
}

}  // namespace icd::fem
