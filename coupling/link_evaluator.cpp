#include <icd/coupling/link_evaluator.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

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

// One link: p = ((a0 q0 + a1 q1) + a2 q2) + c0 e0 + c1 e1 + c2 e2 from the
// triple's 24-double frame packet m and the link's 6 weights w, summed left
// to right on (x, y, z, pad) packets; written to row[0..2].
inline void write_link(const double* m, const double* w, double* row) {
  using Packet = Eigen::Map<const Eigen::Vector4d, Eigen::Aligned16>;
  const Eigen::Vector4d p = w[0] * Packet(m) + w[1] * Packet(m + 4) + w[2] * Packet(m + 8) +
                            w[3] * Packet(m + 12) + w[4] * Packet(m + 16) + w[5] * Packet(m + 20);
  row[0] = p[0];
  row[1] = p[1];
  row[2] = p[2];
}

}  // namespace

LinkEvaluator::LinkEvaluator(const RigidLinks& links, const LinkEvaluatorOptions& options)
    : m_options(options), m_num_coarse_nodes(links.num_coarse_nodes) {
  if (!(options.degenerate_tolerance >= 0.0 && options.degenerate_tolerance < 1.0))
    throw ParameterError("LinkEvaluator: degenerate_tolerance must be in [0, 1), got " +
                         std::to_string(options.degenerate_tolerance));
  validate(links, "LinkEvaluator");
  const int N = links.num_links();
  // Distinct ordered triples, numbered in order of first use (so that the
  // link loop walks the triple table mostly forwards): an open-addressing
  // hash table of triple numbers, at most half full.
  size_t capacity = 16;
  while (capacity < 2 * static_cast<size_t>(N)) capacity *= 2;
  std::vector<int32_t> slot(capacity, -1);
  m_link_triple.resize(N);
  for (int k = 0; k < N; ++k) {
    const int32_t* nodes = &links.nodes(k, 0);  // row-major: three consecutive ints
    uint64_t h = 0;
    for (int i = 0; i < 3; ++i) {  // multiply-xorshift mixing of the three indices
      h = (h ^ static_cast<uint32_t>(nodes[i])) * 0x9E3779B97F4A7C15ull;
      h ^= h >> 29;
    }
    size_t at = h & (capacity - 1);
    for (;; at = (at + 1) & (capacity - 1)) {
      const int32_t t = slot[at];
      if (t < 0) {  // a new triple
        slot[at] = static_cast<int32_t>(m_links_per_triple.size());
        m_links_per_triple.push_back(0);
        m_triple_nodes.insert(m_triple_nodes.end(), nodes, nodes + 3);
        break;
      }
      if (std::equal(nodes, nodes + 3, &m_triple_nodes[3 * static_cast<size_t>(t)])) break;
    }
    m_link_triple[k] = slot[at];
    ++m_links_per_triple[slot[at]];
  }
  const int T0 = num_triples();
  m_triple_offset.assign(static_cast<size_t>(T0) + 1, 0);
  for (int t = 0; t < T0; ++t) m_triple_offset[t + 1] = m_triple_offset[t] + m_links_per_triple[t];
  m_triple_links.resize(N);
  {
    std::vector<int32_t> next(m_triple_offset.begin(), m_triple_offset.end() - 1);
    for (int k = 0; k < N; ++k) m_triple_links[next[m_link_triple[k]]++] = k;
  }
  m_weights.resize(6, N);
  m_weights.topRows(3) = links.alpha.transpose();
  m_weights.bottomRows(3) = links.coeffs.transpose();
  const int T = num_triples();
  m_table.setZero(24, T);
  m_has_frame.assign(T, 0);
}

void LinkEvaluator::reset_frames() { std::fill(m_has_frame.begin(), m_has_frame.end(), 0); }

LinkApplyResult LinkEvaluator::apply(const Eigen::Ref<const MatX3d>& coarse_positions,
                                     Eigen::Ref<MatX3d> dense_out) {
  check_sizes("apply", coarse_positions.rows(), dense_out.rows());
  const LinkApplyResult result =
      update_triples(coarse_positions, num_triples(), [](int i) { return i; });
  evaluate_links(dense_out);
  return result;
}

LinkApplyResult LinkEvaluator::apply_triples(const Eigen::Ref<const MatX3d>& coarse_positions,
                                             const std::vector<int32_t>& triples,
                                             Eigen::Ref<MatX3d> dense_out) {
  const LinkApplyResult result = update_listed("apply_triples", coarse_positions, triples, dense_out);
  const double* table = m_table.data();
  const double* weights = m_weights.data();
  double* out = dense_out.data();
  const Eigen::Index stride = dense_out.outerStride();
  for (int32_t t : triples) {
    const double* m = table + 24 * static_cast<Eigen::Index>(t);
    for (int32_t j = m_triple_offset[t]; j < m_triple_offset[t + 1]; ++j) {
      const int32_t k = m_triple_links[j];
      // (the kernel of evaluate_links(): the same rounding)
      write_link(m, weights + 6 * static_cast<Eigen::Index>(k), out + k * stride);
    }
  }
  return result;
}

LinkApplyResult LinkEvaluator::apply_links(const Eigen::Ref<const MatX3d>& coarse_positions,
                                           const std::vector<int32_t>& triples,
                                           const std::vector<int32_t>& links,
                                           Eigen::Ref<MatX3d> dense_out) {
  if (m_updated_in.size() != m_has_frame.size() || ++m_calls == 0) {  // (wrapped: start again)
    m_updated_in.assign(m_has_frame.size(), 0);
    m_calls = 1;
  }
  for (int32_t t : triples)
    if (t >= 0 && t < num_triples()) m_updated_in[static_cast<size_t>(t)] = m_calls;
  for (int32_t k : links)
    if (k < 0 || k >= num_links() || m_updated_in[static_cast<size_t>(m_link_triple[k])] != m_calls)
      throw ParameterError("LinkEvaluator::apply_links: link " + std::to_string(k) +
                           (k < 0 || k >= num_links() ? " does not exist"
                                                      : " is not a link of the listed triples"));
  const LinkApplyResult result = update_listed("apply_links", coarse_positions, triples, dense_out);
  const double* table = m_table.data();
  const double* weights = m_weights.data();
  double* out = dense_out.data();
  const Eigen::Index stride = dense_out.outerStride();
  for (int32_t k : links)
    write_link(table + 24 * static_cast<Eigen::Index>(m_link_triple[k]),
               weights + 6 * static_cast<Eigen::Index>(k), out + k * stride);
  return result;
}

LinkApplyResult LinkEvaluator::update_listed(const char* who,
                                             const Eigen::Ref<const MatX3d>& coarse_positions,
                                             const std::vector<int32_t>& triples,
                                             const Eigen::Ref<MatX3d>& dense_out) {
  check_sizes(who, coarse_positions.rows(), dense_out.rows());
  for (int32_t t : triples)
    if (t < 0 || t >= num_triples())
      throw ParameterError(std::string("LinkEvaluator::") + who + ": no triple " + std::to_string(t));
  return update_triples(coarse_positions, static_cast<int>(triples.size()),
                        [&](int i) { return triples[static_cast<size_t>(i)]; });
}

void LinkEvaluator::check_sizes(const char* who, Eigen::Index coarse_rows,
                                Eigen::Index dense_rows) const {
  if (coarse_rows != m_num_coarse_nodes)
    throw ParameterError(std::string("LinkEvaluator::") + who + ": coarse_positions has " +
                         std::to_string(coarse_rows) + " rows, the links expect " +
                         std::to_string(m_num_coarse_nodes));
  if (dense_rows != num_links())
    throw ParameterError(std::string("LinkEvaluator::") + who + ": dense_out has " +
                         std::to_string(dense_rows) + " rows, expected " + std::to_string(num_links()));
}

void LinkEvaluator::check_finite(const Eigen::Ref<const MatX3d>& coarse_positions) const {
  for (size_t i = 0; i < m_triple_nodes.size(); ++i) {
    const int32_t v = m_triple_nodes[i];
    if (!coarse_positions.row(v).allFinite())
      throw NumericalError("LinkEvaluator::apply: coarse node " + std::to_string(v) +
                           " has a non-finite position");
  }
}

// Eqs. 4-6 for kLanes triples at a time with Eigen's packet arithmetic
// (sqrt included): the lanes are filled straight from the coarse rows, which
// are also copied into the table for the link loop; the frames go into the
// table, except for degenerate triples, which get fallback_frame(). Throws
// when a node is not finite (before any fallback frame of its chunk).
template <class Index>
LinkApplyResult LinkEvaluator::update_triples(const Eigen::Ref<const MatX3d>& coarse_positions,
                                              int count, Index index) {
  constexpr int kLanes = 2;  // one SSE2 packet: wider lanes spill more than they gain
  static_assert(kLanes == 2, "the gather below fills two lanes");
  using Lane = Eigen::Array<double, kLanes, 1>;
  const double* X = coarse_positions.data();
  const Eigen::Index stride = coarse_positions.outerStride();
  double* table = m_table.data();
  const double tol2 = m_options.degenerate_tolerance * m_options.degenerate_tolerance;
  LinkApplyResult result;
  for (int i0 = 0; i0 < count; i0 += kLanes) {
    // Lane l holds triple index(i0 + l) (the last one repeated past the
    // end); the nodes also go into the table for the link loop.
    const int t0 = index(i0);
    const int t1 = index(std::min(i0 + 1, count - 1));
    const double* rows[2][3];
    for (int i = 0; i < 3; ++i) {
      rows[0][i] = X + m_triple_nodes[3 * t0 + i] * stride;
      rows[1][i] = X + m_triple_nodes[3 * t1 + i] * stride;
    }
    double* col0 = table + 24 * static_cast<Eigen::Index>(t0);
    double* col1 = table + 24 * static_cast<Eigen::Index>(t1);
    for (int i = 0; i < 3; ++i)
      for (int d = 0; d < 3; ++d) {
        col0[4 * i + d] = rows[0][i][d];
        col1[4 * i + d] = rows[1][i][d];
      }
    const auto q = [&](int c) { return Lane(rows[0][c / 3][c % 3], rows[1][c / 3][c % 3]); };
    const Lane ux = q(3) - q(0), uy = q(4) - q(1), uz = q(5) - q(2);
    const Lane vx = q(6) - q(0), vy = q(7) - q(1), vz = q(8) - q(2);
    const Lane nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;  // Eq. 4
    const Lane ax = uy * nz - uz * ny, ay = uz * nx - ux * nz, az = ux * ny - uy * nx;  // Eq. 5
    const Lane nn = nx.square() + ny.square() + nz.square();
    const Lane uu = ux.square() + uy.square() + uz.square();
    const Lane vv = vx.square() + vy.square() + vz.square();
    // Eq. 6: e0 = n / |n|, e1 = (q0 - q1) / |q0 - q1| = -u / |u|, e2 = a / |a|
    // with |a| = |u| |n| (u is orthogonal to n); one division.
    const Lane len_n = nn.sqrt(), len_u = uu.sqrt();
    const Lane inv_a = (len_n * len_u).inverse();
    const Lane inv_n = len_u * inv_a;
    const Lane minus_inv_u = -len_n * inv_a;
    const Lane e[9] = {nx * inv_n,       ny * inv_n, nz * inv_n, ux * minus_inv_u, uy * minus_inv_u,
                       uz * minus_inv_u, ax * inv_a, ay * inv_a, az * inv_a};
    const Eigen::Array<bool, kLanes, 1> ok =
        (nn > 0.0) && (nn > tol2 * uu * vv) && (nn < std::numeric_limits<double>::infinity());
    const int lanes = std::min(kLanes, count - i0);
    const bool all_ok = ok.head(lanes).all();
    // A non-finite node makes |u|^2 or |v|^2 non-finite (so does overflow,
    // which check_finite() lets through as a degenerate frame).
    if (!all_ok && !((uu + vv).head(lanes) < std::numeric_limits<double>::infinity()).all())
      check_finite(coarse_positions);
    for (int l = 0; l < lanes; ++l) {
      const int t = l == 0 ? t0 : t1;
      if (!all_ok && !ok[l]) {  // keeps the previous frame for the fallback
        fallback_frame(t);
        ++result.degenerate_triples;
        result.degenerate_links += m_links_per_triple[t];
        continue;
      }
      double* col = table + 24 * static_cast<Eigen::Index>(t) + 12;
      for (int i = 0; i < 9; ++i) col[4 * (i / 3) + i % 3] = e[i][l];
      m_has_frame[t] = 1;
    }
  }
  return result;
}

void LinkEvaluator::fallback_frame(int t) {
  double* col = m_table.col(t).data();
  const auto load = [&](int offset) { return Vec{col[offset], col[offset + 1], col[offset + 2]}; };
  const Vec q0 = load(0), q1 = load(4);
  Vec e0, e1, e2;
  const Vec d = sub(q0, q1);
  const double dd = dot(d, d);
  if (dd > 0.0 && dd < std::numeric_limits<double>::infinity()) {
    const double len = std::sqrt(dd);
    e1 = {d.x / len, d.y / len, d.z / len};
    Vec cand;
    if (m_has_frame[t]) {
      cand = load(12);
      const double c = dot(cand, e1);
      if (1.0 - c * c < 0.25) cand = load(20);  // e1 turned towards the old e0
    } else {
      // The coordinate axis least aligned with e1.
      const double ax = std::abs(e1.x), ay = std::abs(e1.y), az = std::abs(e1.z);
      cand = ax <= ay && ax <= az ? Vec{1, 0, 0} : (ay <= az ? Vec{0, 1, 0} : Vec{0, 0, 1});
    }
    const double c = dot(cand, e1);
    e0 = normalized(Vec{cand.x - c * e1.x, cand.y - c * e1.y, cand.z - c * e1.z});
    e2 = cross(e0, e1);
  } else if (m_has_frame[t]) {
    e0 = load(12);
    e1 = load(16);
    e2 = load(20);
  } else {
    e0 = {1, 0, 0};
    e1 = {0, 1, 0};
    e2 = {0, 0, 1};
  }
  const Vec e[3] = {e0, e1, e2};
  for (int i = 0; i < 3; ++i) {
    col[12 + 4 * i] = e[i].x;
    col[12 + 4 * i + 1] = e[i].y;
    col[12 + 4 * i + 2] = e[i].z;
  }
  m_has_frame[t] = 1;
}

// p = ((a0 q0 + a1 q1) + a2 q2) + c0 e0 + c1 e1 + c2 e2, summed left to right as
// in apply_reference() (Eqs. 1, 9, 10), on (x, y, z, pad) packets.
void LinkEvaluator::evaluate_links(Eigen::Ref<MatX3d> dense_out) const {
  const int N = num_links();
  const int32_t* triple = m_link_triple.data();
  const double* table = m_table.data();
  const double* weights = m_weights.data();
  double* out = dense_out.data();
  const Eigen::Index stride = dense_out.outerStride();
  for (int k = 0; k < N; ++k) {
    const double* m = table + 24 * static_cast<Eigen::Index>(triple[k]);
    write_link(m, weights + 6 * static_cast<Eigen::Index>(k), out + k * stride);
  }
}

}  // namespace icd::coupling
