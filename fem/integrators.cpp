#include "fem/integrators.hpp"

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

void ExplicitStepper::symplectic_euler(Model& model, State& s, double h) {
  resize(model.num_nodes());
  model.acceleration(s.x, s.v, m_a);
  s.v += h * m_a;
  s.x += h * s.v;  // fixed nodes: v and a stay zero
}

void ExplicitStepper::rk4(Model& model, State& s, double h) {
  resize(model.num_nodes());
  // k1
  model.acceleration(s.x, s.v, m_a);
  m_dx = s.v;
  m_dv = m_a;
  // k2 at y + h/2 k1
  m_x = s.x + 0.5 * h * s.v;
  m_v = s.v + 0.5 * h * m_a;
  model.acceleration(m_x, m_v, m_a);
  m_dx += 2.0 * m_v;
  m_dv += 2.0 * m_a;
  // k3 at y + h/2 k2
  m_x = s.x + 0.5 * h * m_v;
  m_v = s.v + 0.5 * h * m_a;
  model.acceleration(m_x, m_v, m_a);
  m_dx += 2.0 * m_v;
  m_dv += 2.0 * m_a;
  // k4 at y + h k3
  m_x = s.x + h * m_v;
  m_v = s.v + h * m_a;
  model.acceleration(m_x, m_v, m_a);
  m_dx += m_v;
  m_dv += m_a;
  s.x += (h / 6.0) * m_dx;
  s.v += (h / 6.0) * m_dv;
}

}  // namespace icd::fem
