#include <icd/coupling/rigid_links.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <icd/coupling/link_evaluator.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

using Vec3 = Eigen::Vector3d;

/// Static kd-tree over a point set, stored implicitly: the subtree of the index
/// range [lo, hi) has its splitting point at mid = (lo + hi) / 2.
class KdTree {
 public:
  explicit KdTree(std::vector<Vec3> points) : m_points(std::move(points)) {
    m_order.resize(m_points.size());
    for (size_t i = 0; i < m_order.size(); ++i) m_order[i] = static_cast<int>(i);
    m_split_dim.assign(m_points.size(), 0);
    build(0, static_cast<int>(m_order.size()));
  }

  /// The k nearest points to q as (squared distance, point id), sorted by
  /// (distance, id); fewer when the set is smaller.
  void k_nearest(const Vec3& q, int k, std::vector<std::pair<double, int>>& out) const {
    out.clear();
    k = std::min<int>(k, static_cast<int>(m_points.size()));
    if (k <= 0) return;
    search(q, k, 0, static_cast<int>(m_order.size()), out);
    std::sort_heap(out.begin(), out.end());
  }

 private:
  static constexpr int kLeafSize = 8;

  void build(int lo, int hi) {
    if (hi - lo <= kLeafSize) return;
    Vec3 bmin = Vec3::Constant(INFINITY), bmax = Vec3::Constant(-INFINITY);
    for (int i = lo; i < hi; ++i) {
      bmin = bmin.cwiseMin(m_points[m_order[i]]);
      bmax = bmax.cwiseMax(m_points[m_order[i]]);
    }
    int dim = 0;
    (bmax - bmin).maxCoeff(&dim);
    const int mid = (lo + hi) / 2;
    std::nth_element(m_order.begin() + lo, m_order.begin() + mid, m_order.begin() + hi,
                     [&](int a, int b) {
                       const double ca = m_points[a][dim], cb = m_points[b][dim];
                       return ca < cb || (ca == cb && a < b);
                     });
    m_split_dim[mid] = dim;
    build(lo, mid);
    build(mid + 1, hi);
  }

  void offer(const Vec3& q, int id, int k, std::vector<std::pair<double, int>>& heap) const {
    const std::pair<double, int> cand{(m_points[id] - q).squaredNorm(), id};
    if (static_cast<int>(heap.size()) < k) {
      heap.push_back(cand);
      std::push_heap(heap.begin(), heap.end());
    } else if (cand < heap.front()) {
      std::pop_heap(heap.begin(), heap.end());
      heap.back() = cand;
      std::push_heap(heap.begin(), heap.end());
    }
  }

  void search(const Vec3& q, int k, int lo, int hi,
              std::vector<std::pair<double, int>>& heap) const {
    if (hi - lo <= kLeafSize) {
      for (int i = lo; i < hi; ++i) offer(q, m_order[i], k, heap);
      return;
    }
    const int mid = (lo + hi) / 2;
    const int dim = m_split_dim[mid];
    const double diff = q[dim] - m_points[m_order[mid]][dim];
    offer(q, m_order[mid], k, heap);
    if (diff < 0) {
      search(q, k, lo, mid, heap);
      if (static_cast<int>(heap.size()) < k || diff * diff <= heap.front().first)
        search(q, k, mid + 1, hi, heap);
    } else {
      search(q, k, mid + 1, hi, heap);
      if (static_cast<int>(heap.size()) < k || diff * diff <= heap.front().first)
        search(q, k, lo, mid, heap);
    }
  }

  std::vector<Vec3> m_points;
  std::vector<int> m_order;
  std::vector<int> m_split_dim;
};

/// Orthonormal frame (e0, e1, e2) of Eqs. 4-6, as the columns of a matrix.
Eigen::Matrix3d frame(const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  const Vec3 n = (q1 - q0).cross(q2 - q0);  // Eq. 4
  const Vec3 a = (q1 - q0).cross(n);        // Eq. 5
  Eigen::Matrix3d E;
  E.col(0) = n.normalized();  // Eq. 6
  E.col(1) = (q0 - q1).normalized();
  E.col(2) = a.normalized();
  return E;
}

bool collinear(const Vec3& q0, const Vec3& q1, const Vec3& q2, double tol) {
  const double l2 =
      std::max({(q1 - q0).squaredNorm(), (q2 - q0).squaredNorm(), (q2 - q1).squaredNorm()});
  return !(l2 > 0.0) || (q1 - q0).cross(q2 - q0).norm() < tol * l2;
}

}  // namespace

RigidLinks build_rigid_links(const Eigen::Ref<const MatX3d>& P,
                             const Eigen::Ref<const MatX3d>& coarse_rest_positions,
                             const Eigen::Ref<const Eigen::VectorXi>& surface_nodes,
                             const RigidLinkOptions& options) {
  if (!(options.coincident_tolerance >= 0.0) || !(options.collinear_tolerance > 0.0) ||
      !(options.collinear_tolerance < 1.0) || options.initial_candidates < 3)
    throw ParameterError(
        "build_rigid_links: need coincident_tolerance >= 0, 0 < collinear_tolerance < 1, "
        "initial_candidates >= 3");
  const int M = static_cast<int>(coarse_rest_positions.rows());
  const int S = static_cast<int>(surface_nodes.size());
  if (!P.allFinite()) throw InputError("build_rigid_links: dense positions are not finite");
  if (!coarse_rest_positions.allFinite())
    throw InputError("build_rigid_links: coarse rest positions are not finite");
  std::vector<Vec3> pts(S);
  std::vector<char> seen(M, 0);
  for (int s = 0; s < S; ++s) {
    const int v = surface_nodes[s];
    if (v < 0 || v >= M)
      throw ParameterError("build_rigid_links: surface_nodes[" + std::to_string(s) + "] = " +
                           std::to_string(v) + " is outside [0, " + std::to_string(M) + ")");
    if (seen[v])
      throw ParameterError("build_rigid_links: surface node " + std::to_string(v) +
                           " is listed twice");
    seen[v] = 1;
    pts[s] = coarse_rest_positions.row(v).transpose();
  }
  if (S < 3)
    throw InputError("build_rigid_links: need at least 3 coarse surface nodes, got " +
                     std::to_string(S));
  Vec3 bmin = pts[0], bmax = pts[0];
  for (const Vec3& p : pts) {
    bmin = bmin.cwiseMin(p);
    bmax = bmax.cwiseMax(p);
  }
  const double coincident = options.coincident_tolerance * (bmax - bmin).norm();
  const KdTree tree(pts);

  RigidLinks links;
  const int N = static_cast<int>(P.rows());
  links.nodes.resize(N, 3);
  links.alpha.resize(N, 3);
  links.coeffs.resize(N, 3);
  links.num_coarse_nodes = M;
  std::vector<std::pair<double, int>> cand;
  for (int k = 0; k < N; ++k) {
    const Vec3 p = P.row(k).transpose();
    int chosen[3] = {-1, -1, -1};
    for (int K = std::min(options.initial_candidates, S);; K = std::min(2 * K, S)) {
      tree.k_nearest(p, K, cand);
      chosen[0] = cand[0].second;
      chosen[1] = chosen[2] = -1;
      size_t j = 1;
      for (; j < cand.size(); ++j)
        if ((pts[cand[j].second] - pts[chosen[0]]).norm() > coincident) {
          chosen[1] = cand[j].second;
          break;
        }
      for (++j; chosen[1] >= 0 && j < cand.size(); ++j)
        if (!collinear(pts[chosen[0]], pts[chosen[1]], pts[cand[j].second],
                       options.collinear_tolerance)) {
          chosen[2] = cand[j].second;
          break;
        }
      if (chosen[2] >= 0) break;
      if (K == S)
        throw InputError("build_rigid_links: the " + std::to_string(S) +
                         " coarse surface nodes are all collinear or coincident; no link frame "
                         "exists for dense vertex " +
                         std::to_string(k));
    }
    const Vec3 q[3] = {pts[chosen[0]], pts[chosen[1]], pts[chosen[2]]};
    double d[3];  // Eq. 2
    for (int i = 0; i < 3; ++i) d[i] = (q[i] - p).norm();
    const double denom = 2.0 * (d[0] + d[1] + d[2]);  // Eq. 3, normalised
    assert(denom > 0.0);
    const double alpha[3] = {(d[1] + d[2]) / denom, (d[0] + d[2]) / denom, (d[0] + d[1]) / denom};
    const Vec3 O = alpha[0] * q[0] + alpha[1] * q[1] + alpha[2] * q[2];  // Eq. 1
    const Vec3 c = frame(q[0], q[1], q[2]).transpose() * (p - O);        // Eqs. 7-8
    for (int i = 0; i < 3; ++i) {
      links.nodes(k, i) = surface_nodes[chosen[i]];
      links.alpha(k, i) = alpha[i];
      links.coeffs(k, i) = c[i];
    }
  }
  return links;
}

void apply(const RigidLinks& links, const Eigen::Ref<const MatX3d>& coarse_positions,
           Eigen::Ref<MatX3d> dense_out) {
  LinkEvaluator(links).apply(coarse_positions, dense_out);
}

Eigen::SparseMatrix<double, Eigen::RowMajor> origin_matrix(const RigidLinks& links) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(3 * static_cast<size_t>(links.num_links()));
  for (int k = 0; k < links.num_links(); ++k)
    for (int i = 0; i < 3; ++i) entries.emplace_back(k, links.nodes(k, i), links.alpha(k, i));
  Eigen::SparseMatrix<double, Eigen::RowMajor> A(links.num_links(), links.num_coarse_nodes);
  A.setFromTriplets(entries.begin(), entries.end());  // repeated nodes are summed
  return A;
}

void apply_reference(const RigidLinks& links, const Eigen::Ref<const MatX3d>& coarse_positions,
                     Eigen::Ref<MatX3d> dense_out) {
  if (coarse_positions.rows() != links.num_coarse_nodes)
    throw ParameterError("rigid links apply_reference: coarse_positions has " +
                         std::to_string(coarse_positions.rows()) + " rows, the links expect " +
                         std::to_string(links.num_coarse_nodes));
  if (dense_out.rows() != links.nodes.rows())
    throw ParameterError("rigid links apply_reference: dense_out has " +
                         std::to_string(dense_out.rows()) + " rows, expected " +
                         std::to_string(links.nodes.rows()));
  const int N = links.num_links();
  for (int k = 0; k < N; ++k) {
    const Vec3 q0 = coarse_positions.row(links.nodes(k, 0)).transpose();
    const Vec3 q1 = coarse_positions.row(links.nodes(k, 1)).transpose();
    const Vec3 q2 = coarse_positions.row(links.nodes(k, 2)).transpose();
    const Vec3 O = links.alpha(k, 0) * q0 + links.alpha(k, 1) * q1 + links.alpha(k, 2) * q2;
    const Vec3 n = (q1 - q0).cross(q2 - q0);
    const Vec3 a = (q1 - q0).cross(n);
    const Vec3 p = O + links.coeffs(k, 0) * n.normalized() +
                   links.coeffs(k, 1) * (q0 - q1).normalized() +
                   links.coeffs(k, 2) * a.normalized();  // Eqs. 9-10
    dense_out.row(k) = p.transpose();
  }
}

void validate(const RigidLinks& links, const char* what) {
  const auto fail = [&](int row, const std::string& msg) {
    throw InputError(std::string(what) + ": rigid link " + std::to_string(row) + ": " + msg);
  };
  const auto n = links.nodes.rows();
  if (links.alpha.rows() != n || links.coeffs.rows() != n)
    throw InputError(std::string(what) + ": rigid link arrays have different lengths");
  for (Eigen::Index k = 0; k < n; ++k) {
    const int r = static_cast<int>(k);
    for (int i = 0; i < 3; ++i)
      if (links.nodes(k, i) < 0 || links.nodes(k, i) >= links.num_coarse_nodes)
        fail(r, "node index " + std::to_string(links.nodes(k, i)) + " outside [0, " +
                    std::to_string(links.num_coarse_nodes) + ")");
    if (!links.alpha.row(k).allFinite() || !links.coeffs.row(k).allFinite())
      fail(r, "non-finite weight or coefficient");
    if (std::abs(links.alpha.row(k).sum() - 1.0) > 1e-9)
      fail(r, "weights sum to " + std::to_string(links.alpha.row(k).sum()) + ", not 1");
  }
}

}  // namespace icd::coupling
