#include <icd/mesh/spheres/merge_burst.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <queue>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::mesh {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Directions along which each cluster keeps its extreme sample: the maximum
/// distance from a centre to the cluster is estimated on these support points
/// (exact for the union of two clusters: support of a union = best of both).
const MatX3d& support_directions() {
  static const MatX3d dirs = make_icosphere(1, 1.0).V;  // 42 unit vectors
  return dirs;
}

struct Cluster {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double depth = 0;
  double radius = 0;  // exact over members: max |s - c| + gap[s]
  double gmax = 0;    // largest gap of a member
  std::vector<int> members;
  std::vector<int> support;     // one sample per support direction
  std::vector<int> neighbours;  // sorted cluster ids
  std::vector<int> pool;  // initial clusters absorbed (their centres are the merge candidates)
  long long version = 0;
  bool alive = true;
  double error() const { return radius - depth; }
};

/// A candidate operation: merge a and b (b >= 0) or burst a (b = -1).
struct Op {
  double key;
  int a, b;
  long long va, vb;  // versions of a and b (for a burst: vb = sum of the neighbours' versions)
  bool operator<(const Op& o) const {  // max-heap on -key, ties by ids for determinism
    if (key != o.key) return key > o.key;
    if (a != o.a) return a > o.a;
    return b > o.b;
  }
};

class MergeBurst {
 public:
  MergeBurst(const ReductionProblem& problem, const MergeBurstOptions& options)
      : m_problem(problem), m_options(options) {}

  std::vector<std::vector<FittedSphere>> run(const std::vector<int>& owners,
                                             const std::vector<int>& members, int max_k) {
    init(owners, members);
    std::vector<std::vector<FittedSphere>> snapshots(static_cast<size_t>(max_k));
    int alive = static_cast<int>(m_clusters.size());
    if (alive <= max_k) snapshots[static_cast<size_t>(alive - 1)] = snapshot();
    for (int c = 0; c < static_cast<int>(m_clusters.size()); ++c) push_ops_of(c);
    while (alive > 1) {
      if (m_heap.empty()) connect_all();
      if (m_heap.empty()) break;
      const Op op = m_heap.top();
      m_heap.pop();
      if (!m_clusters[static_cast<size_t>(op.a)].alive) continue;
      if (op.b >= 0 && !m_clusters[static_cast<size_t>(op.b)].alive) continue;
      if (!current(op)) {
        // A changed pair was re-queued when it changed; a burst whose
        // neighbourhood changed further away is re-evaluated here.
        if (op.b < 0 && m_clusters[static_cast<size_t>(op.a)].version == op.va) push_op(op.a, -1);
        continue;
      }
      if (op.b >= 0) {
        merge(op.a, op.b);
      } else {
        burst(op.a);
      }
      --alive;
      if (alive <= max_k) snapshots[static_cast<size_t>(alive - 1)] = snapshot();
    }
    return snapshots;
  }

 private:
  Eigen::Vector3d point(int s) const { return m_problem.points.row(s).transpose(); }

  void init(const std::vector<int>& owners, const std::vector<int>& members) {
    std::map<int, int> cluster_of_owner;  // ordered: deterministic cluster ids
    for (int s : members) cluster_of_owner.emplace(owners[static_cast<size_t>(s)], 0);
    int next = 0;
    for (auto& [owner, id] : cluster_of_owner) {
      (void)owner;
      id = next++;
    }
    m_clusters.assign(static_cast<size_t>(next), Cluster{});
    m_centers.resize(next, 3);
    m_depths.resize(next);
    for (const auto& [owner, id] : cluster_of_owner) {
      Cluster& c = m_clusters[static_cast<size_t>(id)];
      c.center = m_problem.medial.centers.row(owner).transpose();
      c.depth = m_problem.medial.radii[owner];
      m_centers.row(id) = c.center.transpose();
      m_depths[id] = c.depth;
    }
    std::vector<int> cluster_of_member(members.size());
    for (size_t m = 0; m < members.size(); ++m) {
      const int id = cluster_of_owner.at(owners[static_cast<size_t>(members[m])]);
      cluster_of_member[m] = id;
      m_clusters[static_cast<size_t>(id)].members.push_back(members[m]);
    }
    for (auto& c : m_clusters) {
      std::sort(c.members.begin(), c.members.end());
      refresh(c);
    }
    // Neighbours: clusters with samples closer than neighbour_radius.
    MatX3d P(static_cast<Eigen::Index>(members.size()), 3);
    for (size_t m = 0; m < members.size(); ++m)
      P.row(static_cast<Eigen::Index>(m)) = m_problem.points.row(members[m]);
    const PointGrid grid(P, m_options.neighbour_radius);
    for (size_t m = 0; m < members.size(); ++m) {
      const int a = cluster_of_member[m];
      for (int n : grid.query_ball(P.row(static_cast<Eigen::Index>(m)).transpose(),
                                   m_options.neighbour_radius)) {
        const int b = cluster_of_member[static_cast<size_t>(n)];
        if (a != b) m_clusters[static_cast<size_t>(a)].neighbours.push_back(b);
      }
    }
    for (size_t c = 0; c < m_clusters.size(); ++c) {
      sort_unique(m_clusters[c].neighbours);
      m_clusters[c].pool = {static_cast<int>(c)};
    }
  }

  static void sort_unique(std::vector<int>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }

  /// Recomputes radius, gap and support of a cluster from its members.
  void refresh(Cluster& c) {
    const MatX3d& dirs = support_directions();
    c.support.assign(static_cast<size_t>(dirs.rows()), -1);
    std::vector<double> best(static_cast<size_t>(dirs.rows()), -kInf);
    c.radius = 0;
    c.gmax = 0;
    for (int s : c.members) {
      const Eigen::Vector3d p = point(s);
      c.radius = std::max(c.radius, (p - c.center).norm() + m_problem.gap[s]);
      c.gmax = std::max(c.gmax, m_problem.gap[s]);
      for (Eigen::Index d = 0; d < dirs.rows(); ++d) {
        const double v = dirs.row(d).dot(p);
        if (v > best[static_cast<size_t>(d)])
          best[static_cast<size_t>(d)] = v, c.support[static_cast<size_t>(d)] = s;
      }
    }
    c.version = ++m_clock;
  }

  /// Best centre for the union of clusters a and b: (error bound, centre index or -1 for a, -2 for
  /// b).
  std::pair<double, int> evaluate_merge(int a, int b) const {
    const Cluster& A = m_clusters[static_cast<size_t>(a)];
    const Cluster& B = m_clusters[static_cast<size_t>(b)];
    const MatX3d& dirs = support_directions();
    std::vector<Eigen::Vector3d> support;
    for (Eigen::Index d = 0; d < dirs.rows(); ++d) {
      const int sa = A.support[static_cast<size_t>(d)], sb = B.support[static_cast<size_t>(d)];
      support.push_back(dirs.row(d).dot(point(sa).transpose()) >=
                                dirs.row(d).dot(point(sb).transpose())
                            ? point(sa)
                            : point(sb));
    }
    std::sort(support.begin(), support.end(),
              [](const Eigen::Vector3d& x, const Eigen::Vector3d& y) {
                return std::lexicographical_compare(x.data(), x.data() + 3, y.data(), y.data() + 3);
              });
    support.erase(std::unique(support.begin(), support.end()), support.end());
    const double gmax = std::max(A.gmax, B.gmax);
    auto cost = [&](const Eigen::Vector3d& c, double depth) {
      double r2 = 0;
      for (const auto& p : support) r2 = std::max(r2, (p - c).squaredNorm());
      return std::sqrt(r2) + gmax - depth;
    };
    double best = cost(A.center, A.depth);
    int best_idx = -1;
    const double cb = cost(B.center, B.depth);
    if (cb < best) best = cb, best_idx = -2;
    // Candidates: the initial centres the two clusters absorbed, evenly thinned.
    const size_t total = A.pool.size() + B.pool.size();
    const size_t limit = static_cast<size_t>(std::max(1, m_options.merge_candidates));
    const size_t stride = total > limit ? (total + limit - 1) / limit : 1;
    for (size_t i = 0; i < total; i += stride) {
      const int m = i < A.pool.size() ? A.pool[i] : B.pool[i - A.pool.size()];
      const double v = cost(m_centers.row(m).transpose(), m_depths[m]);
      if (v < best) best = v, best_idx = m;
    }
    return {best, best_idx};
  }

  /// Error bound after bursting a: the largest error of a neighbour that receives samples.
  double evaluate_burst(int a, std::vector<int>* receiver_of = nullptr) const {
    const Cluster& A = m_clusters[static_cast<size_t>(a)];
    if (A.neighbours.empty()) return kInf;
    std::vector<double> radius;
    for (int n : A.neighbours) radius.push_back(m_clusters[static_cast<size_t>(n)].radius);
    std::vector<char> receives(A.neighbours.size(), 0);
    if (receiver_of != nullptr) receiver_of->assign(A.members.size(), -1);
    for (size_t m = 0; m < A.members.size(); ++m) {
      const int s = A.members[m];
      const Eigen::Vector3d p = point(s);
      double best = kInf;
      size_t best_j = 0;
      for (size_t j = 0; j < A.neighbours.size(); ++j) {
        const Cluster& N = m_clusters[static_cast<size_t>(A.neighbours[j])];
        const double v = std::max(N.radius, (p - N.center).norm() + m_problem.gap[s]) - N.depth;
        if (v < best) best = v, best_j = j;
      }
      const Cluster& N = m_clusters[static_cast<size_t>(A.neighbours[best_j])];
      radius[best_j] = std::max(radius[best_j], (p - N.center).norm() + m_problem.gap[s]);
      receives[best_j] = 1;
      if (receiver_of != nullptr) (*receiver_of)[m] = A.neighbours[best_j];
    }
    double worst = 0;
    for (size_t j = 0; j < A.neighbours.size(); ++j) {
      if (receives[j])
        worst = std::max(worst, radius[j] - m_clusters[static_cast<size_t>(A.neighbours[j])].depth);
    }
    return worst;
  }

  long long neighbourhood_version(int a) const {
    long long sum = 0;
    for (int n : m_clusters[static_cast<size_t>(a)].neighbours)
      sum += m_clusters[static_cast<size_t>(n)].version;
    return sum + static_cast<long long>(m_clusters[static_cast<size_t>(a)].neighbours.size());
  }

  bool current(const Op& op) const {
    const Cluster& A = m_clusters[static_cast<size_t>(op.a)];
    if (op.b >= 0)
      return A.version == op.va && m_clusters[static_cast<size_t>(op.b)].version == op.vb;
    return A.version == op.va && neighbourhood_version(op.a) == op.vb;
  }

  void push_op(int a, int b) {
    if (b >= 0) {
      if (a > b) std::swap(a, b);
      m_heap.push(Op{evaluate_merge(a, b).first, a, b, m_clusters[static_cast<size_t>(a)].version,
                     m_clusters[static_cast<size_t>(b)].version});
    } else if (m_options.allow_burst) {
      const double key = evaluate_burst(a);
      if (key < kInf)
        m_heap.push(
            Op{key, a, -1, m_clusters[static_cast<size_t>(a)].version, neighbourhood_version(a)});
    }
  }

  void push_ops_of(int a) {
    for (int n : m_clusters[static_cast<size_t>(a)].neighbours) {
      if (a < n) push_op(a, n);
    }
    push_op(a, -1);
  }

  /// Last resort when the neighbour graph has several components: every pair becomes a candidate.
  void connect_all() {
    std::vector<int> alive;
    for (int c = 0; c < static_cast<int>(m_clusters.size()); ++c) {
      if (m_clusters[static_cast<size_t>(c)].alive) alive.push_back(c);
    }
    for (size_t i = 0; i < alive.size(); ++i) {
      for (size_t j = i + 1; j < alive.size(); ++j) {
        link(alive[i], alive[j]);
        push_op(alive[i], alive[j]);
      }
    }
  }

  void link(int a, int b) {
    if (a == b) return;
    auto add = [](std::vector<int>& v, int x) {
      auto it = std::lower_bound(v.begin(), v.end(), x);
      if (it == v.end() || *it != x) v.insert(it, x);
    };
    add(m_clusters[static_cast<size_t>(a)].neighbours, b);
    add(m_clusters[static_cast<size_t>(b)].neighbours, a);
  }

  void unlink_all(int a) {
    for (int n : m_clusters[static_cast<size_t>(a)].neighbours) {
      auto& v = m_clusters[static_cast<size_t>(n)].neighbours;
      v.erase(std::remove(v.begin(), v.end(), a), v.end());
    }
    m_clusters[static_cast<size_t>(a)].neighbours.clear();
  }

  void merge(int a, int b) {
    const auto [cost, idx] = evaluate_merge(a, b);
    (void)cost;
    Cluster& A = m_clusters[static_cast<size_t>(a)];
    Cluster& B = m_clusters[static_cast<size_t>(b)];
    if (idx == -2) {
      A.center = B.center, A.depth = B.depth;
    } else if (idx >= 0) {
      A.center = m_centers.row(idx).transpose(), A.depth = m_depths[idx];
    }
    std::vector<int> joined;
    std::merge(A.members.begin(), A.members.end(), B.members.begin(), B.members.end(),
               std::back_inserter(joined));
    A.members = std::move(joined);
    B.members.clear();
    A.pool.insert(A.pool.end(), B.pool.begin(), B.pool.end());
    B.pool.clear();
    B.alive = false;
    const std::vector<int> b_neighbours = B.neighbours;
    unlink_all(b);
    for (int n : b_neighbours) link(a, n);
    refresh(A);
    ++B.version;
    push_ops_of(a);
    for (int n : A.neighbours) push_op(n, -1);
  }

  void burst(int a) {
    std::vector<int> receiver_of;
    evaluate_burst(a, &receiver_of);
    Cluster& A = m_clusters[static_cast<size_t>(a)];
    const std::vector<int> around = A.neighbours;
    std::map<int, int> received;  // receiver -> number of samples
    for (size_t m = 0; m < A.members.size(); ++m) {
      m_clusters[static_cast<size_t>(receiver_of[m])].members.push_back(A.members[m]);
      received[receiver_of[m]] += 1;
    }
    // The burst sphere's candidate centres go to the receiver that took most of its samples.
    int main_receiver = received.begin()->first;
    for (const auto& [r, count] : received) {
      if (count > received[main_receiver]) main_receiver = r;
    }
    auto& pool = m_clusters[static_cast<size_t>(main_receiver)].pool;
    pool.insert(pool.end(), A.pool.begin(), A.pool.end());
    A.members.clear();
    A.alive = false;
    unlink_all(a);
    ++A.version;
    // The burst region is now shared by the spheres that received it: they become neighbours.
    std::vector<int> receivers = receiver_of;
    sort_unique(receivers);
    for (size_t i = 0; i < receivers.size(); ++i) {
      for (size_t j = i + 1; j < receivers.size(); ++j) link(receivers[i], receivers[j]);
    }
    for (int r : receivers) {
      Cluster& R = m_clusters[static_cast<size_t>(r)];
      std::sort(R.members.begin(), R.members.end());
      refresh(R);
    }
    A.pool.clear();
    for (int n : around) push_ops_of(n);
  }

  std::vector<FittedSphere> snapshot() const {
    std::vector<FittedSphere> out;
    for (const Cluster& c : m_clusters) {
      if (!c.alive) continue;
      FittedSphere f;
      f.center = c.center;
      f.depth = c.depth;
      f.radius = c.radius;
      f.error = c.error();
      f.members = c.members;
      out.push_back(std::move(f));
    }
    return out;
  }

  const ReductionProblem& m_problem;
  const MergeBurstOptions& m_options;
  std::vector<Cluster> m_clusters;
  MatX3d m_centers;
  Eigen::VectorXd m_depths;
  std::priority_queue<Op> m_heap;
  long long m_clock = 0;
};

}  // namespace

std::vector<int> medial_owners(const ReductionProblem& problem, double search_radius) {
  if (!(search_radius > 0)) {
    throw ParameterError("medial_owners: search_radius must be positive, got " +
                         std::to_string(search_radius));
  }
  const auto ns = static_cast<int>(problem.points.rows());
  std::vector<int> owners(static_cast<size_t>(ns), -1);
  for (int s = 0; s < ns; ++s) {
    const Eigen::Vector3d p = problem.points.row(s).transpose();
    std::vector<int> cands = problem.medial_grid.query_ball(p, search_radius);
    if (cands.empty()) {
      const int n = problem.medial_grid.nearest(p);
      if (n >= 0) cands.push_back(n);
    }
    double best = kInf;
    for (int m : cands) {
      const double v =
          (p - problem.medial.centers.row(m).transpose()).norm() - problem.medial.radii[m];
      if (v < best) best = v, owners[static_cast<size_t>(s)] = m;
    }
  }
  return owners;
}

std::vector<std::vector<FittedSphere>> merge_burst_reduce(const ReductionProblem& problem,
                                                          const std::vector<int>& owners,
                                                          const std::vector<int>& members,
                                                          int max_k,
                                                          const ReductionOptions& reduction,
                                                          const MergeBurstOptions& options) {
  if (max_k < 1)
    throw ParameterError("merge_burst_reduce: max_k must be >= 1, got " + std::to_string(max_k));
  if (members.empty()) throw ParameterError("merge_burst_reduce: no samples to cover");
  if (!(options.neighbour_radius > 0) || options.merge_candidates < 1 ||
      options.lloyd_iterations < 0) {
    throw ParameterError(
        "MergeBurstOptions: neighbour_radius must be > 0, merge_candidates >= 1, lloyd_iterations "
        ">= 0");
  }
  if (owners.size() != static_cast<size_t>(problem.points.rows())) {
    throw ParameterError("merge_burst_reduce: need one owner per sample (" +
                         std::to_string(problem.points.rows()) + "), got " +
                         std::to_string(owners.size()));
  }
  for (int s : members) {
    const int o = owners[static_cast<size_t>(s)];
    if (o < 0 || o >= problem.medial.centers.rows()) {
      throw ParameterError("merge_burst_reduce: sample " + std::to_string(s) +
                           " has no medial owner");
    }
  }
  MergeBurst mb(problem, options);
  std::vector<std::vector<FittedSphere>> result = mb.run(owners, members, max_k);
  ReductionOptions lloyd = reduction;
  lloyd.lloyd_iterations = options.lloyd_iterations;
  for (int k = 1; k <= max_k; ++k) {
    auto& config = result[static_cast<size_t>(k - 1)];
    if (config.empty()) {  // not met (fewer initial spheres than k): use the next smaller count met
      continue;
    }
    refine_jointly(problem, config, lloyd);
    config.erase(std::remove_if(config.begin(), config.end(),
                                [](const FittedSphere& s) { return s.members.empty(); }),
                 config.end());
  }
  // Counts above the number of initial spheres were never met: repeat the largest configuration.
  for (int k = 2; k <= max_k; ++k) {
    if (result[static_cast<size_t>(k - 1)].empty())
      result[static_cast<size_t>(k - 1)] = result[static_cast<size_t>(k - 2)];
  }
  assert(!result.front().empty());
  return result;
}

}  // namespace icd::mesh
