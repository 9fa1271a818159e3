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

void ExplicitStepper::symplectic_euler(Model& model, State& s, double h) {
  symplectic_euler(model, s, m_out, h);
  s.x.swap(m_out.x);
  s.v.swap(m_out.v);
}

void ExplicitStepper::symplectic_euler(Model& model, const State& in, State& out, double h,
                                       ElementHealth* start_health) {
  assert(&in != &out);
  const int n = model.num_nodes();
  resize(n);
  fit(out, n);
  model.acceleration(in.x, in.v, m_a, start_health);
  const double* x = in.x.data();
  const double* v = in.v.data();
  const double* a = m_a.data();
  double* x1 = out.x.data();
  double* v1 = out.v.data();
  for (long k = 0; k < 3L * n; ++k) {  // fixed nodes: v and a stay zero
    v1[k] = v[k] + h * a[k];
    x1[k] = x[k] + h * v1[k];
  }
}

void ExplicitStepper::rk4(Model& model, State& s, double h) {
  rk4(model, s, m_out, h);
  s.x.swap(m_out.x);
  s.v.swap(m_out.v);
}

void ExplicitStepper::rk4(Model& model, const State& in, State& out, double h, ElementHealth* start_health) {
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
  model.acceleration(in.x, in.v, m_a, start_health);
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
