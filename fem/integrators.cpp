#include <icd/fem/integrators.hpp>

#include <bit>
#include <cassert>
#include <cstdint>
#include <utility>

#include <icd/fem/lane_loops.hpp>

namespace icd::fem {

const char* to_string(Integrator integrator) {
  switch (integrator) {
    case Integrator::RK4:
      return "rk4";
    case Integrator::SymplecticEuler:
      return "symplectic_euler";
    case Integrator::BackwardEuler:
      return "backward_euler";
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

namespace {

// Sums of m v_k^2 and load_k x_k over the dofs k = 3i + c in 4 interleaved
// partial sums (dof k into sum k % 4, combined as (s0 + s1) + (s2 + s3)):
// the compiler vectorises them, where a single running sum made every dof
// wait for the previous one's addition.
struct EnergySums {
  double kinetic[4] = {0, 0, 0, 0};
  double work[4] = {0, 0, 0, 0};
  [[gnu::always_inline]] void add(int j, double m, double v, double load, double x) {
    kinetic[j] += m * v * v;
    work[j] += load * x;
  }
  StateEnergies result() const {
    return {0.5 * ((kinetic[0] + kinetic[1]) + (kinetic[2] + kinetic[3])),
            -((work[0] + work[1]) + (work[2] + work[3]))};
  }
};

}  // namespace

StateEnergies state_energies(const Model& model, const State& s) {
  assert(s.x.rows() == model.num_nodes() && s.v.rows() == model.num_nodes());
  const long nd = 3L * model.num_nodes();
  const double* m = model.dof_mass().data();
  const double* load = model.loads().data();
  const double* x = s.x.data();
  const double* v = s.v.data();
  EnergySums sums;
  long k = 0;
  for (; k + 4 <= nd; k += 4)
    for (int j = 0; j < 4; ++j) sums.add(j, m[k + j], v[k + j], load[k + j], x[k + j]);
  for (; k < nd; ++k) sums.add(static_cast<int>(k & 3), m[k], v[k], load[k], x[k]);
  return sums.result();
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

// Dofs k0 .. k0 + count - 1 of a symplectic Euler node pass (count <= 4, k0
// a multiple of 4; kCount > 0: count = kCount, known to the compiler), dof
// k0 + j into the partial sums j. The acceleration is Model::acceleration's
// formula, exactly zero at fixed dofs even where the elastic force is not
// finite: a bit mask, not a product with 0, and not a branch (with a select,
// GCC emitted a branch and did not vectorise). Restrict-qualified pointers.
template <bool kEnergies, int kCount>
[[gnu::always_inline]] inline void symplectic_euler_dofs(
    int count, double alpha, double h, const double* __restrict m, const double* __restrict w,
    const std::uint64_t* __restrict free_mask, const double* __restrict load,
    const double* __restrict x, const double* __restrict v, const double* __restrict f,
    double* __restrict x1, double* __restrict v1, EnergySums& sums) {
  for (int j = 0; j < (kCount > 0 ? kCount : count); ++j) {
    if constexpr (kEnergies) sums.add(j, m[j], v[j], load[j], x[j]);
    const double a_free = w[j] * (f[j] + load[j] - m[j] * alpha * v[j]);
    const double a = std::bit_cast<double>(std::bit_cast<std::uint64_t>(a_free) & free_mask[j]);
    const double vj = v[j] + h * a;
    v1[j] = vj;
    x1[j] = x[j] + h * vj;
  }
}

// The node pass of a symplectic Euler step (see ExplicitStepper::symplectic_euler);
// kEnergies: also the StateEnergies of (x, v), summed as in state_energies().
struct NodePass {
  long nd;
  double alpha, h;
  const double *m, *w;
  const std::uint64_t* free_mask;
  const double *load, *x, *v, *f;
  double *x1, *v1;
};

template <bool kEnergies>
[[gnu::always_inline]] inline StateEnergies symplectic_euler_nodes_body(const NodePass& p) {
  EnergySums sums;
  long k = 0;
  for (; k + 4 <= p.nd; k += 4)
    symplectic_euler_dofs<kEnergies, 4>(4, p.alpha, p.h, p.m + k, p.w + k, p.free_mask + k,
                                        p.load + k, p.x + k, p.v + k, p.f + k, p.x1 + k, p.v1 + k,
                                        sums);
  symplectic_euler_dofs<kEnergies, 0>(static_cast<int>(p.nd - k), p.alpha, p.h, p.m + k, p.w + k,
                                      p.free_mask + k, p.load + k, p.x + k, p.v + k, p.f + k,
                                      p.x1 + k, p.v1 + k, sums);
  return sums.result();
}

// The pass compiled for the baseline instruction set and for AVX2 (without
// FMA: the same operations, bitwise the same results), chosen like the lane
// loops (lanes::lane_isa()); measured ~2x faster with AVX2 (perf: 6.7% of a
// symplectic Euler run on the fem_realtime bar with the baseline build).
template <bool kEnergies>
StateEnergies symplectic_euler_nodes_baseline(const NodePass& p) {
  return symplectic_euler_nodes_body<kEnergies>(p);
}
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
template <bool kEnergies>
__attribute__((target("avx2"))) StateEnergies symplectic_euler_nodes_avx2(const NodePass& p) {
  return symplectic_euler_nodes_body<kEnergies>(p);
}
#endif

template <bool kEnergies>
StateEnergies symplectic_euler_nodes(const Model& model, const double* x, const double* v,
                                     const double* f, double h, double* x1, double* v1) {
  const NodePass p{3L * model.num_nodes(),
                   model.damping().alpha,
                   h,
                   model.dof_mass().data(),
                   model.dof_inverse_mass().data(),
                   model.dof_free_mask().data(),
                   model.loads().data(),
                   x,
                   v,
                   f,
                   x1,
                   v1};
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  if (lanes::lane_isa() == lanes::LaneIsa::AVX2) return symplectic_euler_nodes_avx2<kEnergies>(p);
#endif
  return symplectic_euler_nodes_baseline<kEnergies>(p);
}

}  // namespace

void ExplicitStepper::symplectic_euler(Model& model, const State& in, State& out, double h,
                                       const StepExtras& extras) {
  assert(&in != &out);
  const int n = model.num_nodes();
  resize(n);
  fit(out, n);
  model.element_forces(in.x, in.v, m_a, extras.health, extras.elastic, extras.oriented);
  if (extras.energies)
    *extras.energies = symplectic_euler_nodes<true>(model, in.x.data(), in.v.data(), m_a.data(), h,
                                                    out.x.data(), out.v.data());
  else
    symplectic_euler_nodes<false>(model, in.x.data(), in.v.data(), m_a.data(), h, out.x.data(),
                                  out.v.data());
}

void ExplicitStepper::rk4(Model& model, State& s, double h) {
  rk4(model, s, m_out, h);
  s.x.swap(m_out.x);
  s.v.swap(m_out.v);
}

void ExplicitStepper::rk4(Model& model, const State& in, State& out, double h,
                          ElementHealth* start_health) {
  StepExtras extras;
  extras.health = start_health;
  rk4(model, in, out, h, extras);
}

void ExplicitStepper::rk4(Model& model, const State& in, State& out, double h,
                          const StepExtras& extras) {
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
  model.acceleration(in.x, in.v, m_a, extras.health, extras.elastic, extras.oriented);
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
