#pragma once
/// Time integrators of a Model: RK4 (the paper's), symplectic Euler (one force
/// evaluation per step) and backward Euler (see backward_euler.hpp).
#include <icd/fem/model.hpp>

namespace icd::fem {

/// Time integration scheme.
enum class Integrator {
  RK4,              ///< classical 4th-order Runge-Kutta on (x, v) (paper section 3)
  SymplecticEuler,  ///< v += h a(x, v); x += h v (central differences)
  BackwardEuler     ///< implicit, Newton + CHOLMOD; unconditionally stable
};

/// "rk4", "symplectic_euler", "backward_euler".
const char* to_string(Integrator integrator);

/// Dynamic state of one object.
struct State {
  MatX3d x;  ///< positions (#V x 3), m
  MatX3d v;  ///< velocities (#V x 3), m/s
};

/// Kinetic energy 1/2 sum m |v|^2 and potential of the conservative loads
/// -sum (f_ext + m g) . x of a state, J (Model::kinetic_energy and
/// Model::load_potential in a fixed order of their own, dof k = 3i + c into
/// the partial sum k % 4: equal to them up to rounding, deterministic). Not
/// finite if any entry of x or v is not.
struct StateEnergies {
  double kinetic = 0;
  double load = 0;
};

/// StateEnergies of s in one pass over the nodes.
StateEnergies state_energies(const Model& model, const State& s);

/// Optional extras of an explicit step about its input state, computed in the
/// passes the step makes anyway (the Simulator's health checks use them).
struct StepExtras {
  /// Out: the ElementHealth of in.x, from the element pass of the first force
  /// evaluation (which is at in.x).
  ElementHealth* health = nullptr;
  /// Out: the StateEnergies of in, from the first pass over the nodes.
  StateEnergies* energies = nullptr;
  /// In: f_int(in.x) (#V x 3, N) computed before (a health check at in.x):
  /// used instead of the first force evaluation. Not with `health`.
  const MatX3d* elastic = nullptr;
  /// Out: whether every element of in.x has det F > 0 (false where one is
  /// <= 0 or NaN), from the element pass of the first force evaluation: the
  /// cheap alternative to `health` (not with `health` or `elastic`).
  bool* oriented = nullptr;
};

/// Explicit steppers with their scratch buffers (no allocation per step once
/// the buffers have the model's size). The out-of-place forms write the new
/// state into `out` (a different object than `in`, resized if needed) and,
/// when start_health is given, return the ElementHealth of in.x computed in
/// the same element pass as the first force evaluation (which is at in.x):
/// the Simulator's health checks cost no extra force evaluation.
class ExplicitStepper {
 public:
  /// One symplectic Euler step of size h (s): v1 = v0 + h a(x0, v0), x1 = x0 + h v1.
  /// One force evaluation (two with stiffness damping), then one pass over the
  /// nodes that forms a = M^-1 (f + loads - alpha m v0) (0 at fixed nodes),
  /// v1, x1 and the extras' energies of the input (bitwise the state of
  /// Model::acceleration followed by the update formula).
  void symplectic_euler(Model& model, State& s, double h);
  void symplectic_euler(Model& model, const State& in, State& out, double h,
                        ElementHealth* start_health = nullptr);
  void symplectic_euler(Model& model, const State& in, State& out, double h,
                        const StepExtras& extras);
  /// One classical RK4 step of size h on y = (x, v), y' = (v, a(x, v)): four evaluations.
  void rk4(Model& model, State& s, double h);
  void rk4(Model& model, const State& in, State& out, double h,
           ElementHealth* start_health = nullptr);
  void rk4(Model& model, const State& in, State& out, double h, const StepExtras& extras);

 private:
  void resize(int n);
  MatX3d m_a, m_x, m_v, m_dx, m_dv;
  State m_out;
};

}  // namespace icd::fem
