#include "coupling/link_evaluator.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "mesh/io/error.hpp"

namespace icd::coupling {
namespace {

// Slots of the per-triple scalars (each an array of #T doubles): the nodes
// q0, q1, q2, then the frame e0, e1, e2, each x, y, z.
constexpr int kQ0 = 0, kQ1 = 3, kQ2 = 6, kE0 = 9, kE1 = 12, kE2 = 15;

struct Vec {
  double x, y, z;
};

Vec sub(const Vec& a, const Vec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec cross(const Vec& a, const Vec& b) {  // same operation order as Eigen's cross()
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double dot(const Vec& a, const Vec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
// As Eigen's normalized(): v / |v|, or v itself when |v| == 0.
Vec normalized(const Vec& v) {
  const double z = dot(v, v);
  if (!(z > 0.0)) return v;
  const double s = std::sqrt(z);
  return {v.x / s, v.y / s, v.z / s};
}

}  // namespace

LinkEvaluator::LinkEvaluator(const RigidLinks& links, const LinkEvaluatorOptions& options)
    : m_options(options), m_num_coarse_nodes(links.num_coarse_nodes) {
  if (!(options.degenerate_tolerance >= 0.0 && options.degenerate_tolerance < 1.0))
    throw ParameterError("LinkEvaluator: degenerate_tolerance must be in [0, 1), got " +
                         std::to_string(options.degenerate_tolerance));
  validate(links, "LinkEvaluator");
  const int N = links.num_links();
  m_order.resize(N);
  std::iota(m_order.begin(), m_order.end(), 0);
  const auto key = [&](int32_t k) {
    return std::array<int32_t, 4>{links.nodes(k, 0), links.nodes(k, 1), links.nodes(k, 2), k};
  };
  std::sort(m_order.begin(), m_order.end(), [&](int32_t a, int32_t b) { return key(a) < key(b); });

  m_group_offset.push_back(0);
  for (int j = 0; j < N; ++j) {
    const int32_t k = m_order[j];
    if (j > 0 && links.nodes.row(k) != links.nodes.row(m_order[j - 1])) m_group_offset.push_back(j);
    if (m_group_offset.size() > m_triple_nodes.size() / 3)
      for (int i = 0; i < 3; ++i) m_triple_nodes.push_back(links.nodes(k, i));
  }
  m_group_offset.push_back(N);
  if (N == 0) m_group_offset.assign(1, 0);
  const int T = num_triples();
  assert(static_cast<int>(m_triple_nodes.size()) == 3 * T);

  m_weights.resize(6 * static_cast<size_t>(N));
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < 3; ++i) {
      m_weights[i * static_cast<size_t>(N) + j] = links.alpha(m_order[j], i);
      m_weights[(3 + i) * static_cast<size_t>(N) + j] = links.coeffs(m_order[j], i);
    }
  m_triple.assign(kTripleScalars * static_cast<size_t>(T), 0.0);
  m_degenerate.assign(T, 0);
  m_has_frame.assign(T, 0);
  m_out.resize(3 * static_cast<size_t>(N));
}

void LinkEvaluator::reset_frames() { std::fill(m_has_frame.begin(), m_has_frame.end(), 0); }

LinkApplyResult LinkEvaluator::apply(const Eigen::Ref<const MatX3d>& coarse_positions,
                                     Eigen::Ref<MatX3d> dense_out) {
  if (coarse_positions.rows() != m_num_coarse_nodes)
    throw ParameterError("LinkEvaluator::apply: coarse_positions has " +
                         std::to_string(coarse_positions.rows()) + " rows, the links expect " +
                         std::to_string(m_num_coarse_nodes));
  if (dense_out.rows() != num_links())
    throw ParameterError("LinkEvaluator::apply: dense_out has " + std::to_string(dense_out.rows()) +
                         " rows, expected " + std::to_string(num_links()));
  gather_nodes(coarse_positions);
  LinkApplyResult result;
  result.degenerate_triples = compute_frames();
  if (result.degenerate_triples > 0) {
    for (int t = 0; t < num_triples(); ++t)
      if (m_degenerate[t]) {
        fallback_frame(t);
        result.degenerate_links += m_group_offset[t + 1] - m_group_offset[t];
      }
  }
  evaluate_links();

  const int N = num_links();
  const double* __restrict x = m_out.data();
  const double* __restrict y = x + N;
  const double* __restrict z = y + N;
  const int32_t* __restrict order = m_order.data();
  double* out = dense_out.data();
  const Eigen::Index stride = dense_out.outerStride();
  for (int j = 0; j < N; ++j) {
    double* row = out + order[j] * stride;
    row[0] = x[j];
    row[1] = y[j];
    row[2] = z[j];
  }
  return result;
}

void LinkEvaluator::gather_nodes(const Eigen::Ref<const MatX3d>& coarse_positions) {
  const int T = num_triples();
  double* q = m_triple.data();
  bool finite = true;
  for (int t = 0; t < T; ++t)
    for (int i = 0; i < 3; ++i) {
      const int32_t v = m_triple_nodes[3 * t + i];
      for (int d = 0; d < 3; ++d) {
        const double c = coarse_positions(v, d);
        finite = finite && std::isfinite(c);
        q[(3 * i + d) * static_cast<size_t>(T) + t] = c;
      }
    }
  if (finite) return;
  for (int t = 0; t < T; ++t)
    for (int i = 0; i < 3; ++i) {
      const int32_t v = m_triple_nodes[3 * t + i];
      if (!coarse_positions.row(v).allFinite())
        throw NumericalError("LinkEvaluator::apply: coarse node " + std::to_string(v) +
                             " has a non-finite position");
    }
}

int LinkEvaluator::compute_frames() {
  const int T = num_triples();
  const double tol = m_options.degenerate_tolerance;
  double* s = m_triple.data();
  const auto at = [&](int slot, int t) -> double& { return s[slot * static_cast<size_t>(T) + t]; };
  int degenerate = 0;
  for (int t = 0; t < T; ++t) {
    const Vec q0{at(kQ0, t), at(kQ0 + 1, t), at(kQ0 + 2, t)};
    const Vec q1{at(kQ1, t), at(kQ1 + 1, t), at(kQ1 + 2, t)};
    const Vec q2{at(kQ2, t), at(kQ2 + 1, t), at(kQ2 + 2, t)};
    const Vec u = sub(q1, q0), v = sub(q2, q0);
    const Vec n = cross(u, v);  // Eq. 4
    const double nn = dot(n, n);
    const bool bad = !(std::sqrt(nn) > tol * std::sqrt(dot(u, u)) * std::sqrt(dot(v, v)) &&
                       nn < std::numeric_limits<double>::infinity());
    m_degenerate[t] = bad;
    if (bad) {
      ++degenerate;
      continue;  // keep the previous frame for fallback_frame()
    }
    const Vec a = cross(u, n);                                                 // Eq. 5
    const Vec e[3] = {normalized(n), normalized(sub(q0, q1)), normalized(a)};  // Eq. 6
    for (int i = 0; i < 3; ++i) {
      at(kE0 + 3 * i, t) = e[i].x;
      at(kE0 + 3 * i + 1, t) = e[i].y;
      at(kE0 + 3 * i + 2, t) = e[i].z;
    }
    m_has_frame[t] = 1;
  }
  return degenerate;
}

void LinkEvaluator::fallback_frame(int t) {
  const int T = num_triples();
  double* s = m_triple.data();
  const auto at = [&](int slot) -> double& { return s[slot * static_cast<size_t>(T) + t]; };
  const auto load = [&](int slot) { return Vec{at(slot), at(slot + 1), at(slot + 2)}; };
  const Vec q0 = load(kQ0), q1 = load(kQ1);
  Vec e0, e1, e2;
  const Vec d = sub(q0, q1);
  const double dd = dot(d, d);
  if (dd > 0.0) {
    const double len = std::sqrt(dd);
    e1 = {d.x / len, d.y / len, d.z / len};
    Vec cand;
    if (m_has_frame[t]) {
      cand = load(kE0);
      const double c = dot(cand, e1);
      if (1.0 - c * c < 0.25) cand = load(kE2);  // e1 turned towards the old e0
    } else {
      // The coordinate axis least aligned with e1.
      const double ax = std::abs(e1.x), ay = std::abs(e1.y), az = std::abs(e1.z);
      cand = ax <= ay && ax <= az ? Vec{1, 0, 0} : (ay <= az ? Vec{0, 1, 0} : Vec{0, 0, 1});
    }
    const double c = dot(cand, e1);
    e0 = normalized(Vec{cand.x - c * e1.x, cand.y - c * e1.y, cand.z - c * e1.z});
    e2 = cross(e0, e1);
  } else if (m_has_frame[t]) {
    e0 = load(kE0);
    e1 = load(kE1);
    e2 = load(kE2);
  } else {
    e0 = {1, 0, 0};
    e1 = {0, 1, 0};
    e2 = {0, 0, 1};
  }
  const Vec e[3] = {e0, e1, e2};
  for (int i = 0; i < 3; ++i) {
    at(kE0 + 3 * i) = e[i].x;
    at(kE0 + 3 * i + 1) = e[i].y;
    at(kE0 + 3 * i + 2) = e[i].z;
  }
  m_has_frame[t] = 1;
}

void LinkEvaluator::evaluate_links() {
  const int T = num_triples();
  const size_t N = m_order.size();
  const double* __restrict w = m_weights.data();
  const double* __restrict a0 = w;
  const double* __restrict a1 = w + N;
  const double* __restrict a2 = w + 2 * N;
  const double* __restrict c0 = w + 3 * N;
  const double* __restrict c1 = w + 4 * N;
  const double* __restrict c2 = w + 5 * N;
  double* __restrict px = m_out.data();
  double* __restrict py = px + N;
  double* __restrict pz = py + N;
  const double* s = m_triple.data();
  double m[kTripleScalars];
  for (int t = 0; t < T; ++t) {
    for (int k = 0; k < kTripleScalars; ++k) m[k] = s[k * static_cast<size_t>(T) + t];
    const int32_t end = m_group_offset[t + 1];
    // p = ((a0 q0 + a1 q1) + a2 q2) + c0 e0 + c1 e1 + c2 e2, left to right
    // as in apply_reference() (Eqs. 1, 9, 10).
    for (int32_t j = m_group_offset[t]; j < end; ++j) {
      px[j] = a0[j] * m[kQ0] + a1[j] * m[kQ1] + a2[j] * m[kQ2] + c0[j] * m[kE0] + c1[j] * m[kE1] +
              c2[j] * m[kE2];
      py[j] = a0[j] * m[kQ0 + 1] + a1[j] * m[kQ1 + 1] + a2[j] * m[kQ2 + 1] + c0[j] * m[kE0 + 1] +
              c1[j] * m[kE1 + 1] + c2[j] * m[kE2 + 1];
      pz[j] = a0[j] * m[kQ0 + 2] + a1[j] * m[kQ1 + 2] + a2[j] * m[kQ2 + 2] + c0[j] * m[kE0 + 2] +
              c1[j] * m[kE1 + 2] + c2[j] * m[kE2 + 2];
    }
  }
}

}  // namespace icd::coupling
