#include <icd/mesh/pipeline/tet_cleanup.hpp>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/core/triangle_geometry.hpp>
#include <icd/mesh/pipeline/fem_step.hpp>
#include <icd/mesh/pipeline/tet_quality.hpp>

namespace icd::mesh {
namespace {

using Tet = std::array<int, 4>;

double tet_volume(const MatX3d& V, const Tet& t) {
  const Eigen::Vector3d a = V.row(t[0]), b = V.row(t[1]), c = V.row(t[2]), d = V.row(t[3]);
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

/// The stiffness block and lumped mass a tet adds to each of its nodes
/// (linear elasticity, the scene's default density and Young's modulus).
struct NodeBlocks {
  double lambda = 0, mu = 0, density = 0;
  explicit NodeBlocks(double poisson) {
    fem::Material m;
    m.poisson = poisson;
    const double E = m.young, nu = m.poisson;
    lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    mu = E / (2 * (1 + nu));
    density = m.density;
  }
  /// Adds tet t's contributions to K[v] and mass[v] of its nodes v with
  /// keep(v), in the node order of t.
  template <class Keep>
  void add(const MatX3d& V, const Tet& t, std::vector<Eigen::Matrix3d>& K, Eigen::VectorXd& mass,
           const Keep& keep) const {
    Eigen::Matrix3d Dm;
    for (int k = 0; k < 3; ++k) Dm.col(k) = (V.row(t[k + 1]) - V.row(t[0])).transpose();
    const double vol = Dm.determinant() / 6.0;
    const Eigen::Matrix3d G = Dm.inverse();  // rows: gradients of nodes 1..3
    for (int a = 0; a < 4; ++a) {
      if (!keep(t[a])) continue;
      const Eigen::Vector3d g =
          a == 0 ? Eigen::Vector3d(-G.colwise().sum().transpose()) : Eigen::Vector3d(G.row(a - 1));
      K[static_cast<size_t>(t[a])] +=
          vol * ((lambda + mu) * g * g.transpose() + mu * g.squaredNorm() * Eigen::Matrix3d::Identity());
      mass[t[a]] += density * vol / 4.0;
    }
  }
  static double frequency(const Eigen::Matrix3d& K, double mass) {
    if (!(mass > 0)) return 0.0;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(K, Eigen::EigenvaluesOnly);
    return std::sqrt(std::max(0.0, es.eigenvalues()[2]) / mass);
  }
};

/// Node frequencies sqrt(lambda_max(K_ii) / m_i) (linear elasticity, lumped
/// mass), rad/s, for the scene's default density and Young's modulus; 0 for
/// unused nodes.
Eigen::VectorXd node_frequencies(const MatX3d& V, const std::vector<Tet>& T, double poisson) {
  const NodeBlocks nb(poisson);
  const Eigen::Index n = V.rows();
  std::vector<Eigen::Matrix3d> K(static_cast<size_t>(n), Eigen::Matrix3d::Zero());
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(n);
  for (const Tet& t : T) nb.add(V, t, K, mass, [](int) { return true; });
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < n; ++i) w[i] = NodeBlocks::frequency(K[static_cast<size_t>(i)], mass[i]);
  return w;
}

/// node_frequencies(V, T, poisson)[v] for the nodes v of `nodes` only (the
/// same sums in the same order: the same bits), and whether each is in a
/// tet of T; O(|T|) without a decomposition per node.
void node_frequencies_of(const MatX3d& V, const std::vector<Tet>& T, double poisson,
                         const std::set<int>& nodes, std::vector<double>& w,
                         std::vector<char>& used) {
  const NodeBlocks nb(poisson);
  const size_t n = static_cast<size_t>(V.rows());
  std::vector<char> flag(n, 0);
  for (int v : nodes) flag[static_cast<size_t>(v)] = 1;
  std::vector<Eigen::Matrix3d> K(n);
  Eigen::VectorXd mass(static_cast<Eigen::Index>(n));
  for (int v : nodes) {
    K[static_cast<size_t>(v)].setZero();
    mass[v] = 0;
  }
  const auto keep = [&](int v) { return flag[static_cast<size_t>(v)] != 0; };
  used.assign(nodes.size(), 0);
  for (const Tet& t : T)
    if (keep(t[0]) || keep(t[1]) || keep(t[2]) || keep(t[3])) {
      nb.add(V, t, K, mass, keep);
      for (int v : t)
        if (keep(v)) flag[static_cast<size_t>(v)] = 2;
    }
  w.clear();
  size_t k = 0;
  for (int v : nodes) {
    used[k++] = flag[static_cast<size_t>(v)] == 2;
    w.push_back(NodeBlocks::frequency(K[static_cast<size_t>(v)], mass[v]));
  }
}

struct Topology {
  bool ok = false;
  long euler = 0;
  int components = 0;
};

/// Whether every face is in at most two tets and the boundary is a closed
/// edge-manifold surface; its Euler characteristic and components.
Topology topology(const std::vector<Tet>& T, int num_nodes) {
  Topology topo;
  std::unordered_map<std::uint64_t, int> faces;
  faces.reserve(T.size() * 4);
  const auto key3 = [&](int a, int b, int c) {
    int s[3] = {a, b, c};
    std::sort(s, s + 3);
    return (static_cast<std::uint64_t>(s[0]) * num_nodes + s[1]) * num_nodes + s[2];
  };
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (const Tet& t : T)
    for (const auto& f : kFace)
      if (++faces[key3(t[f[0]], t[f[1]], t[f[2]])] > 2) return topo;
  std::unordered_map<std::uint64_t, int> edges;
  std::vector<int> parent(static_cast<size_t>(num_nodes));
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int x) {
    while (parent[static_cast<size_t>(x)] != x)
      x = parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    return x;
  };
  std::set<int> verts;
  long nf = 0;
  for (const auto& [k, n] : faces) {
    if (n != 1) continue;
    ++nf;
    const int v[3] = {static_cast<int>(k / (static_cast<std::uint64_t>(num_nodes) * num_nodes)),
                      static_cast<int>(k / num_nodes % num_nodes), static_cast<int>(k % num_nodes)};
    for (int e = 0; e < 3; ++e) {
      const int a = std::min(v[e], v[(e + 1) % 3]), b = std::max(v[e], v[(e + 1) % 3]);
      ++edges[static_cast<std::uint64_t>(a) * num_nodes + b];
      verts.insert(v[e]);
      parent[static_cast<size_t>(find(a))] = find(b);
    }
  }
  for (const auto& [k, n] : edges)
    if (n != 2) return topo;
  std::set<int> roots;
  for (int v : verts) roots.insert(find(v));
  topo.ok = true;
  topo.euler = static_cast<long>(verts.size()) - static_cast<long>(edges.size()) + nf;
  topo.components = static_cast<int>(roots.size());
  return topo;
}

double min_dihedral(const MatX3d& V, const Tet& t) {
  const TetShape s = tet_shape(V.row(t[0]).transpose(), V.row(t[1]).transpose(),
                               V.row(t[2]).transpose(), V.row(t[3]).transpose());
  return *std::min_element(s.dihedral_deg, s.dihedral_deg + 6);
}

// Node i moved to x: the volume change of its tets `around` and the largest
// node frequency of the mesh then (the step bound); V is left as it was.
struct TrialMove {
  double volume_change = 0;
  double max_frequency = 0;
};
TrialMove trial_move(MatX3d& V, const std::vector<Tet>& T, const std::vector<int>& around, int i,
                     const Eigen::Vector3d& x, double poisson) {
  const Eigen::RowVector3d keep = V.row(i);
  TrialMove m;
  for (int t : around) m.volume_change -= tet_volume(V, T[static_cast<size_t>(t)]);
  V.row(i) = x.transpose();
  for (int t : around) m.volume_change += tet_volume(V, T[static_cast<size_t>(t)]);
  m.max_frequency = node_frequencies(V, T, poisson).maxCoeff();
  V.row(i) = keep;
  return m;
}

// Smallest dihedral angle of the tets `around` node i with i at x, -1 when
// one of them is not positive; V is left as it was.
double star_min_dihedral(MatX3d& V, const std::vector<Tet>& T, const std::vector<int>& around,
                         int i, const Eigen::Vector3d& x) {
  const Eigen::RowVector3d keep = V.row(i);
  V.row(i) = x.transpose();
  double d = 180;
  for (int e : around) {
    if (!(tet_volume(V, T[static_cast<size_t>(e)]) > 0)) {
      d = -1;
      break;
    }
    d = std::min(d, min_dihedral(V, T[static_cast<size_t>(e)]));
  }
  V.row(i) = keep;
  return d;
}

}  // namespace

double ideal_omega(double mean_volume, double poisson) {
  StableStepOptions o;
  o.material.poisson = poisson;
  o.material.model = fem::MaterialModel::Linear;
  const TetMesh ideal = bcc_block(o.ideal_cells, std::cbrt(12.0 * mean_volume));
  return stable_step_report(ideal, o).omega_max;
}

StepCleanupReport raise_stable_step(TetMesh& mesh, const StepCleanupOptions& o) {
  if (!(o.target_ratio >= 0) || !(o.max_shift >= 0) || !(o.max_volume_change >= 0) ||
      o.max_collapses < 0 || o.max_relocation_sweeps < 0 || !(o.poisson > -1 && o.poisson < 0.5) ||
      !(o.dihedral_volume_change >= 0) || !(o.max_off_surface >= 0))
    throw ParameterError("raise_stable_step: need target_ratio, max_shift, max_volume_change, "
                         "dihedral_volume_change, max_off_surface, max_collapses, "
                         "max_relocation_sweeps >= 0 and poisson in (-1, 0.5)");
  StepCleanupReport rep;
  const int n = static_cast<int>(mesh.V.rows());
  if (mesh.T.rows() == 0 || o.target_ratio == 0) return rep;
  std::vector<Tet> T(static_cast<size_t>(mesh.T.rows()));
  for (Eigen::Index e = 0; e < mesh.T.rows(); ++e)
    for (int k = 0; k < 4; ++k) T[static_cast<size_t>(e)][k] = mesh.T(e, k);
  double volume0 = 0;
  double dmin = 180;
  for (const Tet& t : T) {
    volume0 += tet_volume(mesh.V, t);
    dmin = std::min(dmin, min_dihedral(mesh.V, t));
  }
  dmin = std::min(dmin, o.min_dihedral_deg);
  const double ideal = ideal_omega(volume0 / static_cast<double>(T.size()), o.poisson);
  const double threshold = ideal / o.target_ratio;
  const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  const Topology topo0 = topology(T, n);
  if (!topo0.ok) return rep;  // not a mesh this pass can keep valid
  double volume = volume0;
  // The volume bound: max_volume_change from the start; in the dihedral
  // phases also anything within dihedral_volume_change of where the step
  // phase left it.
  bool dihedral_phase = false;
  double volume_d0 = volume0;
  const auto volume_ok = [&](double vol) {
    if (std::abs(vol / volume0 - 1) <= o.max_volume_change) return true;
    return dihedral_phase && std::abs(vol - volume_d0) <= o.dihedral_volume_change * volume0;
  };
  Eigen::VectorXd w = node_frequencies(mesh.V, T, o.poisson);
  rep.ratio_before = ideal / w.maxCoeff();
  // Positions of the surface as it was, where a peel or collapse moved it:
  // each must stay within max_shift * diagonal of the current boundary (a
  // bound on the cumulative change, not only on each step's).
  std::vector<Eigen::Vector3d> moved;
  // ... and every point of the new boundary near the change (vertices, edge
  // midpoints, centroids of its faces at `touched` nodes) within it of the
  // original boundary: a peel may expose faces of interior nodes.
  const double lim2 = std::pow(o.max_shift * diagonal, 2);
  const auto near_surface = [&](const MatX3i& F, const Eigen::Vector3d& p) {
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      const Eigen::Vector3d a = mesh.V.row(F(f, 0)), b = mesh.V.row(F(f, 1)), c = mesh.V.row(F(f, 2));
      if ((closest_point_on_triangle(p, a, b, c) - p).squaredNorm() <= lim2) return true;
    }
    return false;
  };
  const MatX3i F0 = boundary_faces(mesh.T);
  const auto within = [&](const std::vector<Tet>& cand, const std::vector<Eigen::Vector3d>& pts,
                          const std::set<int>& touched) {
    MatX4i Tc(static_cast<Eigen::Index>(cand.size()), 4);
    for (size_t e = 0; e < cand.size(); ++e)
      for (int k = 0; k < 4; ++k) Tc(static_cast<Eigen::Index>(e), k) = cand[e][k];
    const MatX3i Fc = boundary_faces(Tc);
    for (const Eigen::Vector3d& p : pts)
      if (!near_surface(Fc, p)) return false;
    for (Eigen::Index f = 0; f < Fc.rows(); ++f) {
      if (!touched.count(Fc(f, 0)) && !touched.count(Fc(f, 1)) && !touched.count(Fc(f, 2)))
        continue;
      const Eigen::Vector3d a = mesh.V.row(Fc(f, 0)), b = mesh.V.row(Fc(f, 1)), c = mesh.V.row(Fc(f, 2));
      for (const Eigen::Vector3d& p : {a, b, c, Eigen::Vector3d((a + b) / 2), Eigen::Vector3d((b + c) / 2),
                                       Eigen::Vector3d((c + a) / 2), Eigen::Vector3d((a + b + c) / 3)})
        if (!near_surface(F0, p)) return false;
    }
    return true;
  };
  // The mesh around the current T: node -> tets, surface nodes and edges.
  struct Local {
    std::vector<std::vector<int>> around;
    std::vector<char> surface;
    std::set<std::pair<int, int>> bedges;
  };
  const auto local = [&] {
    Local L;
    L.around.resize(static_cast<size_t>(n));
    for (size_t e = 0; e < T.size(); ++e)
      for (int v : T[e]) L.around[static_cast<size_t>(v)].push_back(static_cast<int>(e));
    MatX4i Tm(static_cast<Eigen::Index>(T.size()), 4);
    for (size_t e = 0; e < T.size(); ++e)
      for (int k = 0; k < 4; ++k) Tm(static_cast<Eigen::Index>(e), k) = T[e][k];
    const MatX3i F = boundary_faces(Tm);
    L.surface.assign(static_cast<size_t>(n), 0);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        L.surface[static_cast<size_t>(F(f, k))] = 1;
        L.bedges.insert(std::minmax(F(f, k), F(f, (k + 1) % 3)));
      }
    return L;
  };
  const auto neighbours = [&](const Local& L, int i) {
    std::set<int> nbrs;
    for (int e : L.around[static_cast<size_t>(i)])
      for (int v : T[static_cast<size_t>(e)])
        if (v != i) nbrs.insert(v);
    return nbrs;
  };
  // A move of node i: collapse into a neighbour j, or, for a surface node,
  // peel (j = -1): remove every tet of i, the surface receding to the faces
  // opposite i (i's thin tets hold little volume). Valid when every tet it
  // changes stays positive with smallest dihedral angle >= floor_deg, the
  // volume, topology and surface bounds hold; `worst` is the largest node
  // frequency it leaves around i, `dihedral` the smallest angle of the tets
  // it changes (180 when it only removes tets).
  struct Move {
    std::vector<Tet> T;
    double volume = 0, worst = 0, dihedral = 180;
  };
  // `promising(worst, dihedral)`: whether the caller would take a move with
  // these figures; checked before the topology and surface checks (most
  // candidate moves fail it: on rotor's wrap the pass took 34 s with those
  // checks first).
  const auto evaluate = [&](const Local& L, const std::set<int>& nbrs, int i, int j,
                            double floor_deg, Move& out, const auto& promising) {
    const bool surf = L.surface[static_cast<size_t>(i)] != 0;
    if (j >= 0 && surf && !L.bedges.count(std::minmax(i, j))) return false;
    if (j >= 0 && surf && (mesh.V.row(i) - mesh.V.row(j)).norm() > o.max_shift * diagonal)
      return false;
    if (j < 0) {  // the height of i over each opposite face: how far the surface moves
      for (int e : L.around[static_cast<size_t>(i)]) {
        const Tet& t = T[static_cast<size_t>(e)];
        int k = 0;
        while (t[k] != i) ++k;
        const Eigen::Vector3d a = mesh.V.row(t[(k + 1) % 4]), b = mesh.V.row(t[(k + 2) % 4]),
                              c = mesh.V.row(t[(k + 3) % 4]), p = mesh.V.row(i);
        const Eigen::Vector3d nrm = (b - a).cross(c - a);
        if (std::abs(nrm.normalized().dot(p - a)) > o.max_shift * diagonal) return false;
      }
    }
    Move m;
    m.T.reserve(T.size());
    double vol = volume;
    for (size_t e = 0; e < T.size(); ++e) {
      Tet t = T[e];
      const bool has_i = std::find(t.begin(), t.end(), i) != t.end();
      if (!has_i) {
        m.T.push_back(t);
        continue;
      }
      vol -= tet_volume(mesh.V, t);
      if (j < 0 || std::find(t.begin(), t.end(), j) != t.end()) continue;  // removed
      std::replace(t.begin(), t.end(), i, j);
      const double v = tet_volume(mesh.V, t);
      if (!(v > 0)) return false;
      const double d = min_dihedral(mesh.V, t);
      if (d < floor_deg) return false;
      m.dihedral = std::min(m.dihedral, d);
      vol += v;
      m.T.push_back(t);
    }
    if (!volume_ok(vol)) return false;
    // The largest node frequency around i: the tets the move changes hold
    // i's neighbours only (j is one of them).
    std::vector<double> wc;
    std::vector<char> used;
    node_frequencies_of(mesh.V, m.T, o.poisson, nbrs, wc, used);
    double worst = 0.0;
    for (size_t k = 0; k < wc.size(); ++k) {
      worst = std::max(worst, wc[k]);
      if (j < 0 && !used[k]) worst = INFINITY;  // a node left without a tet
    }
    if (!promising(worst, m.dihedral)) return false;
    const Topology topo = topology(m.T, n);
    if (!topo.ok || topo.euler != topo0.euler || topo.components != topo0.components) return false;
    {  // an interior collapse may expose nothing; the check is cheap
      std::vector<Eigen::Vector3d> pts = moved;
      if (surf) pts.emplace_back(mesh.V.row(i).transpose());
      if (!within(m.T, pts, nbrs)) return false;
    }
    m.volume = vol;
    m.worst = worst;
    out = std::move(m);
    return true;
  };
  const auto apply = [&](const Local& L, int i, Move& m) {
    if (L.surface[static_cast<size_t>(i)]) moved.emplace_back(mesh.V.row(i).transpose());
    T = std::move(m.T);
    volume = m.volume;
    w = node_frequencies(mesh.V, T, o.poisson);
  };
  std::set<int> stuck;
  long attempts = 0;  // nodes tried: bounded whatever the mesh
  // The mesh around T, rebuilt only after a move changed T (a node found
  // stuck changes nothing: rotor's wrap had 614 of them).
  Local cached;
  bool fresh = false;
  while (rep.collapses < o.max_collapses && attempts++ < 4L * n) {
    if (!fresh) cached = local();
    fresh = true;
    const Local& L = cached;
    // The worst node not known to be stuck.
    int i = -1;
    for (int v = 0; v < n; ++v)
      if (w[v] > threshold && !stuck.count(v) && (i < 0 || w[v] > w[i])) i = v;
    if (i < 0) break;
    const std::set<int> nbrs = neighbours(L, i);
    Move best;
    best.worst = w[i];
    bool found = false;
    std::vector<int> options(nbrs.begin(), nbrs.end());
    if (L.surface[static_cast<size_t>(i)]) options.push_back(-1);
    for (int j : options) {
      Move m;
      if (evaluate(L, nbrs, i, j, dmin, m,
                   [&](double worst, double) { return worst < best.worst; })) {
        best = std::move(m);
        found = true;
      }
    }
    if (!found) {
      stuck.insert(i);
      continue;
    }
    apply(L, i, best);
    fresh = false;
    ++rep.collapses;
    // A collapse changes the tets of i's neighbours only: they may have new
    // moves; a node stuck elsewhere stays stuck (retrying every stuck node
    // after each collapse made the pass quadratic: 35 s on a meshed cube).
    for (int v : nbrs) stuck.erase(v);
  }
  // Second phase: the tets below the dihedral target (the smallest first),
  // by the same moves of one of their nodes, under the same bounds, where the
  // move leaves every tet it changes with a larger smallest angle than the
  // tet removed and the largest node frequency no higher than the target's
  // or today's (the step does not get worse).
  rep.min_dihedral_before = 180;
  for (const Tet& t : T) rep.min_dihedral_before = std::min(rep.min_dihedral_before, min_dihedral(mesh.V, t));
  dihedral_phase = true;
  volume_d0 = volume;
  std::set<Tet> stuck_tets;
  while (o.dihedral_target_deg > 0 && rep.collapses + rep.dihedral_collapses < o.max_collapses &&
         attempts++ < 8L * n) {
    int bad = -1;
    double angle = o.dihedral_target_deg;
    for (size_t e = 0; e < T.size(); ++e) {
      const double d = min_dihedral(mesh.V, T[e]);
      if (d < angle) {
        Tet key = T[e];
        std::sort(key.begin(), key.end());
        if (stuck_tets.count(key)) continue;
        angle = d;
        bad = static_cast<int>(e);
      }
    }
    if (bad < 0) break;
    if (!fresh) cached = local();
    fresh = true;
    const Local& L = cached;
    const double cap = std::max(threshold, w.maxCoeff());
    Move best;
    int best_i = -1;
    std::set<int> best_nbrs;
    for (int i : T[static_cast<size_t>(bad)]) {
      const std::set<int> nbrs = neighbours(L, i);
      std::vector<int> options(nbrs.begin(), nbrs.end());
      if (L.surface[static_cast<size_t>(i)]) options.push_back(-1);
      for (int j : options) {
        Move m;
        if (evaluate(L, nbrs, i, j, std::nextafter(angle, 180.0), m,
                     [&](double worst, double dihedral) {
                       return worst <= cap && (best_i < 0 || dihedral > best.dihedral);
                     })) {
          best = std::move(m);
          best_i = i;
          best_nbrs = nbrs;
        }
      }
    }
    if (best_i < 0) {
      Tet key = T[static_cast<size_t>(bad)];
      std::sort(key.begin(), key.end());
      stuck_tets.insert(key);
      continue;
    }
    apply(L, best_i, best);
    fresh = false;
    ++rep.dihedral_collapses;
  }
  // Flips and drops of the tets below the dihedral target (the smallest
  // first): a 2-3 flip across one of its faces, the removal of one of its
  // edges when that edge's tets form a closed ring of 3..7 (the ring
  // polygon re-triangulated as a fan from each of its corners, joined to the
  // edge's two ends), or, with a face on the boundary, the tet dropped. Each
  // flip keeps the region (checked: positive tets, the same volume, the
  // same boundary) and is taken when its new tets' smallest angle beats the
  // sliver's; a drop keeps the bounds of the collapses. Flips that reach the
  // target come first, then a drop, then any flip that improves.
  const auto topological_phase = [&] {
    if (o.dihedral_target_deg <= 0 || !o.flips) return;
    const auto key_of = [](Tet t) {
      std::sort(t.begin(), t.end());
      return t;
    };
    const auto has = [](const Tet& t, int v) { return std::find(t.begin(), t.end(), v) != t.end(); };
    std::set<Tet> stuck_flip;
    struct Cand {
      std::vector<int> removed;  // indices into T
      std::vector<Tet> added;
      double score = 0;          // smallest angle of the added tets (drops: the target)
      bool drop = false;
    };
    for (long guard = 0; guard < 4L * static_cast<long>(T.size()) + 16; ++guard) {
      int bad = -1;
      double angle = o.dihedral_target_deg;
      for (size_t e = 0; e < T.size(); ++e) {
        const double d = min_dihedral(mesh.V, T[e]);
        if (d < angle && !stuck_flip.count(key_of(T[e]))) {
          angle = d;
          bad = static_cast<int>(e);
        }
      }
      if (bad < 0) break;
      const Local L = local();
      const double cap = std::max(threshold, w.maxCoeff());
      const Tet t = T[static_cast<size_t>(bad)];
      std::vector<Cand> cands;
      const auto oriented = [&](Tet x) {  // positive orientation, or x[0] = -1 when flat
        const double v = tet_volume(mesh.V, x);
        if (v < 0) std::swap(x[2], x[3]);
        if (v == 0) x[0] = -1;
        return x;
      };
      const auto score_of = [&](const std::vector<Tet>& added) {
        double d = 180;
        for (const Tet& x : added) {
          if (x[0] < 0 || !(tet_volume(mesh.V, x) > 0)) return -1.0;
          d = std::min(d, min_dihedral(mesh.V, x));
        }
        return d;
      };
      bool on_boundary = false;
      static constexpr int kOpp[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
      for (int k = 0; k < 4; ++k) {  // 2-3 flips across each face
        const int p0 = t[kOpp[k][0]], p1 = t[kOpp[k][1]], p2 = t[kOpp[k][2]];
        int other = -1;
        for (int e : L.around[static_cast<size_t>(p0)])
          if (e != bad && has(T[static_cast<size_t>(e)], p1) && has(T[static_cast<size_t>(e)], p2)) other = e;
        if (other < 0) {
          on_boundary = true;
          continue;
        }
        int b = -1;
        for (int v : T[static_cast<size_t>(other)])
          if (v != p0 && v != p1 && v != p2) b = v;
        const int a = t[k];
        Cand c;
        c.removed = {bad, other};
        // Consistent orientation: every (a, b, p, q) along the face's cycle has one sign.
        const int cyc[3] = {p0, p1, p2};
        int sign = 0;
        bool ok = true;
        for (int m = 0; m < 3 && ok; ++m) {
          const double v = tet_volume(mesh.V, Tet{a, b, cyc[m], cyc[(m + 1) % 3]});
          const int sg = v > 0 ? 1 : v < 0 ? -1 : 0;
          if (sg == 0 || (sign != 0 && sg != sign)) ok = false;
          sign = sg;
          c.added.push_back(oriented(Tet{a, b, cyc[m], cyc[(m + 1) % 3]}));
        }
        if (!ok) continue;
        c.score = score_of(c.added);
        if (c.score > angle) cands.push_back(std::move(c));
      }
      for (int ea = 0; ea < 4; ++ea)  // removal of each edge with a closed ring
        for (int eb = ea + 1; eb < 4; ++eb) {
          const int a = t[ea], b = t[eb];
          std::vector<int> ring_tets;
          for (int e : L.around[static_cast<size_t>(a)])
            if (has(T[static_cast<size_t>(e)], b)) ring_tets.push_back(e);
          if (ring_tets.size() < 3 || ring_tets.size() > 7) continue;
          std::map<int, int> next;
          bool ok = true;
          for (int e : ring_tets) {
            int cd[2], m = 0;
            for (int v : T[static_cast<size_t>(e)])
              if (v != a && v != b) cd[m++] = v;
            if (tet_volume(mesh.V, Tet{a, b, cd[0], cd[1]}) < 0) std::swap(cd[0], cd[1]);
            if (!next.emplace(cd[0], cd[1]).second) ok = false;
          }
          if (!ok) continue;
          std::vector<int> ring{next.begin()->first};
          while (ring.size() <= ring_tets.size()) {
            const auto it = next.find(ring.back());
            if (it == next.end()) break;
            ring.push_back(it->second);
          }
          // Closed: back at the start after exactly |ring_tets| steps.
          if (ring.size() != ring_tets.size() + 1 || ring.back() != ring.front()) continue;
          ring.pop_back();
          const int k = static_cast<int>(ring.size());
          for (int apex = 0; apex < (k == 3 ? 1 : k); ++apex) {
            Cand c;
            c.removed = ring_tets;
            int sa = 0;
            bool good = true;
            for (int j = 1; j + 1 < k && good; ++j) {
              const int p = ring[static_cast<size_t>(apex)], q = ring[static_cast<size_t>((apex + j) % k)],
                        r = ring[static_cast<size_t>((apex + j + 1) % k)];
              const double va = tet_volume(mesh.V, Tet{p, q, r, a}), vb = tet_volume(mesh.V, Tet{p, q, r, b});
              const int ga = va > 0 ? 1 : va < 0 ? -1 : 0, gb = vb > 0 ? 1 : vb < 0 ? -1 : 0;
              if (ga == 0 || gb != -ga || (sa != 0 && ga != sa)) good = false;
              sa = ga;
              c.added.push_back(oriented(Tet{p, q, r, a}));
              c.added.push_back(oriented(Tet{p, q, r, b}));
            }
            if (!good) continue;
            c.score = score_of(c.added);
            if (c.score > angle) cands.push_back(std::move(c));
          }
        }
      if (on_boundary) {
        Cand c;
        c.removed = {bad};
        c.score = o.dihedral_target_deg;
        c.drop = true;
        cands.push_back(std::move(c));
      }
      // Best first: flips reaching the target above a drop, a drop above
      // flips that only improve.
      std::stable_sort(cands.begin(), cands.end(), [](const Cand& x, const Cand& y) {
        return x.score > y.score || (x.score == y.score && x.drop && !y.drop);
      });
      bool applied = false;
      for (Cand& c : cands) {
        std::vector<Tet> nt;
        nt.reserve(T.size() + c.added.size());
        double removed_volume = 0, added_volume = 0;
        std::vector<char> gone(T.size(), 0);
        for (int e : c.removed) {
          gone[static_cast<size_t>(e)] = 1;
          removed_volume += tet_volume(mesh.V, T[static_cast<size_t>(e)]);
        }
        for (size_t e = 0; e < T.size(); ++e)
          if (!gone[e]) nt.push_back(T[e]);
        for (const Tet& x : c.added) {
          added_volume += tet_volume(mesh.V, x);
          nt.push_back(x);
        }
        std::set<int> touched;
        for (int e : c.removed)
          for (int v : T[static_cast<size_t>(e)]) touched.insert(v);
        std::vector<Eigen::Vector3d> pts = moved;
        if (c.drop) {
          if (!volume_ok(volume - removed_volume)) continue;
          for (int k = 0; k < 4; ++k)  // the dropped boundary faces' centroids
            pts.push_back((mesh.V.row(t[kOpp[k][0]]) + mesh.V.row(t[kOpp[k][1]]) + mesh.V.row(t[kOpp[k][2]]))
                              .transpose() / 3.0);
        } else if (std::abs(added_volume - removed_volume) > 1e-9 * removed_volume) {
          continue;  // not the same region
        }
        const Topology topo = topology(nt, n);
        if (!topo.ok || topo.euler != topo0.euler || topo.components != topo0.components) continue;
        if (c.drop && !within(nt, pts, touched)) continue;
        const Eigen::VectorXd wc = node_frequencies(mesh.V, nt, o.poisson);
        bool capped = true;
        for (int v : touched)
          if (wc[v] > cap) capped = false;
        if (!capped) continue;
        if (c.drop) {
          for (int k = 0; k < 4; ++k) {  // record the surface as it was
            const int f0 = t[kOpp[k][0]], f1 = t[kOpp[k][1]], f2 = t[kOpp[k][2]];
            bool shared = false;
            for (int e : L.around[static_cast<size_t>(f0)])
              if (e != bad && has(T[static_cast<size_t>(e)], f1) && has(T[static_cast<size_t>(e)], f2))
                shared = true;
            if (!shared)
              moved.emplace_back((mesh.V.row(f0) + mesh.V.row(f1) + mesh.V.row(f2)).transpose() / 3.0);
          }
          volume -= removed_volume;
          ++rep.drops;
        } else {
          ++rep.flips;
        }
        T = std::move(nt);
        w = wc;
        applied = true;
        break;
      }
      if (!applied) stuck_flip.insert(key_of(t));
    }
  };
  topological_phase();
  // Third phase: the tets still below the dihedral target (collapses found
  // no valid move) get one of their nodes relocated, the connectivity kept:
  // an interior node anywhere, a surface node along the boundary as it was
  // before this phase (projected onto it, at most max_shift of the diagonal
  // from where it was); accepted when the smallest angle of the node's tets
  // rises, every tet stays positive, no node frequency rises above
  // max(the target's, the mesh's largest) and the volume bound holds.
  if (o.dihedral_target_deg > 0 && o.max_relocation_sweeps > 0) {
    const Local L = local();
    const MatX3d V0 = mesh.V;  // the boundary as it was: surface nodes stay on it
    MatX4i Tm(static_cast<Eigen::Index>(T.size()), 4);
    for (size_t e = 0; e < T.size(); ++e)
      for (int k = 0; k < 4; ++k) Tm(static_cast<Eigen::Index>(e), k) = T[e][k];
    const MatX3i Fb = boundary_faces(Tm);
    std::vector<std::vector<int>> bfaces(static_cast<size_t>(n));
    for (Eigen::Index f = 0; f < Fb.rows(); ++f)
      for (int k = 0; k < 3; ++k) bfaces[static_cast<size_t>(Fb(f, k))].push_back(static_cast<int>(f));
    const auto project = [&](const Eigen::Vector3d& p) {
      Eigen::Vector3d best = p;
      double d2 = INFINITY;
      for (Eigen::Index f = 0; f < Fb.rows(); ++f) {
        const Eigen::Vector3d q = closest_point_on_triangle(
            p, V0.row(Fb(f, 0)).transpose(), V0.row(Fb(f, 1)).transpose(), V0.row(Fb(f, 2)).transpose());
        if ((q - p).squaredNorm() < d2) {
          d2 = (q - p).squaredNorm();
          best = q;
        }
      }
      return best;
    };
    const double cap = std::max(threshold, w.maxCoeff());
    // Smallest angle of i's tets with i at x (-1 when one is not positive).
    const auto star_min = [&](int i, const Eigen::Vector3d& x) {
      return star_min_dihedral(mesh.V, T, L.around[static_cast<size_t>(i)], i, x);
    };
    // The best of a few candidate positions of node i, or false.
    const auto relocate = [&](int i, Eigen::Vector3d& to, double& gain) {
      const bool surf = L.surface[static_cast<size_t>(i)] != 0;
      const Eigen::Vector3d x = mesh.V.row(i).transpose();
      const double now = star_min(i, x);
      const std::set<int> nbrs = neighbours(L, i);
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      double mean_edge = 0;
      int nc = 0;
      for (int v : nbrs) {
        mean_edge += (mesh.V.row(v) - mesh.V.row(i)).norm();
        if (surf && !L.bedges.count(std::minmax(i, v))) continue;
        c += mesh.V.row(v).transpose();
        ++nc;
      }
      if (nbrs.empty() || nc == 0) return false;
      mean_edge /= static_cast<double>(nbrs.size());
      c /= nc;
      std::vector<Eigen::Vector3d> cand;
      for (double s : {1.0, 0.6, 0.3}) cand.push_back(x + s * (c - x));
      // Along the gradient of the worst tet's smallest angle (finite differences).
      int worst = -1;
      double dw = 181;
      for (int e : L.around[static_cast<size_t>(i)]) {
        const double d = min_dihedral(mesh.V, T[static_cast<size_t>(e)]);
        if (d < dw) {
          dw = d;
          worst = e;
        }
      }
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      const double h = 1e-4 * mean_edge;
      for (int k = 0; k < 3; ++k) {
        const Eigen::RowVector3d keep = mesh.V.row(i);
        mesh.V(i, k) += h;
        const double up = min_dihedral(mesh.V, T[static_cast<size_t>(worst)]);
        mesh.V(i, k) -= 2 * h;
        const double down = min_dihedral(mesh.V, T[static_cast<size_t>(worst)]);
        mesh.V.row(i) = keep;
        g[k] = (up - down) / (2 * h);
      }
      if (surf) {  // in the tangent plane of the boundary around i
        Eigen::Vector3d nrm = Eigen::Vector3d::Zero();
        for (int f : bfaces[static_cast<size_t>(i)]) {
          const Eigen::Vector3d a = V0.row(Fb(f, 0)), b = V0.row(Fb(f, 1)), cc = V0.row(Fb(f, 2));
          nrm += (b - a).cross(cc - a);
        }
        if (nrm.norm() > 0) g -= g.dot(nrm.normalized()) * nrm.normalized();
      }
      if (g.norm() > 0)
        for (double s : {0.03, 0.06, 0.12, 0.25})
          cand.push_back(x + s * mean_edge * g.normalized());
      bool found = false;
      double best = now;
      for (Eigen::Vector3d p : cand) {
        if (surf) {
          p = project(p);
          if ((p - V0.row(i).transpose()).norm() > o.max_shift * diagonal) continue;
        }
        const double d = star_min(i, p);
        if (d > best + 1e-9) {
          best = d;
          to = p;
          found = true;
        }
      }
      gain = best - now;
      return found;
    };
    for (int sweep = 0; sweep < o.max_relocation_sweeps; ++sweep) {
      std::vector<std::pair<double, int>> bad;
      for (size_t e = 0; e < T.size(); ++e) {
        const double d = min_dihedral(mesh.V, T[e]);
        if (d < o.dihedral_target_deg) bad.emplace_back(d, static_cast<int>(e));
      }
      std::sort(bad.begin(), bad.end());
      int moved_now = 0;
      for (const auto& [d0, e] : bad) {
        if (min_dihedral(mesh.V, T[static_cast<size_t>(e)]) >= o.dihedral_target_deg) continue;
        int best_i = -1;
        double best_gain = 0, best_dv = 0;
        Eigen::Vector3d best_to = Eigen::Vector3d::Zero();
        for (int i : T[static_cast<size_t>(e)]) {
          Eigen::Vector3d to;
          double gain = 0;
          if (relocate(i, to, gain) && gain > best_gain) {
            // The step and volume bounds at the new position.
            const TrialMove m = trial_move(mesh.V, T, L.around[static_cast<size_t>(i)], i, to, o.poisson);
            if (m.max_frequency > cap || !volume_ok(volume + m.volume_change)) continue;
            best_i = i;
            best_gain = gain;
            best_to = to;
            best_dv = m.volume_change;
          }
        }
        if (best_i < 0) continue;
        mesh.V.row(best_i) = best_to.transpose();
        volume += best_dv;
        ++rep.relocations;
        ++moved_now;
      }
      if (moved_now == 0) break;
    }
    if (rep.relocations > 0) w = node_frequencies(mesh.V, T, o.poisson);
  }
  if (rep.relocations > 0) topological_phase();
  // Last phase, only when tets below the target remain: their nodes move
  // again, a surface node now also off the boundary (within max_off_surface
  // of the diagonal of the boundary as it was before this phase), along the
  // gradient of the sliver's smallest angle or along the boundary's normal;
  // accepted as the relocations are (the smallest angle of the node's tets
  // rises, positive tets, the node-frequency cap, the volume bound).
  const auto below_target = [&] {
    for (const Tet& t : T)
      if (min_dihedral(mesh.V, t) < o.dihedral_target_deg) return true;
    return false;
  };
  if (o.dihedral_target_deg > 0 && o.max_off_surface > 0 && o.max_relocation_sweeps > 0 &&
      below_target()) {
    const Local L = local();
    MatX4i Tm(static_cast<Eigen::Index>(T.size()), 4);
    for (size_t e = 0; e < T.size(); ++e)
      for (int k = 0; k < 4; ++k) Tm(static_cast<Eigen::Index>(e), k) = T[e][k];
    const MatX3i Fb = boundary_faces(Tm);
    const MatX3d V1 = mesh.V;
    const double budget = o.max_off_surface * diagonal;
    const auto off_boundary = [&](const Eigen::Vector3d& p) {  // distance to the boundary before
      double d2 = INFINITY;
      for (Eigen::Index f = 0; f < Fb.rows(); ++f)
        d2 = std::min(d2, (closest_point_on_triangle(p, V1.row(Fb(f, 0)).transpose(),
                                                     V1.row(Fb(f, 1)).transpose(),
                                                     V1.row(Fb(f, 2)).transpose()) -
                           p).squaredNorm());
      return std::sqrt(d2);
    };
    const auto star_min = [&](int i, const Eigen::Vector3d& x) {
      return star_min_dihedral(mesh.V, T, L.around[static_cast<size_t>(i)], i, x);
    };
    const double cap = std::max(threshold, w.maxCoeff());
    for (int sweep = 0; sweep < 2 * o.max_relocation_sweeps; ++sweep) {
      std::vector<std::pair<double, int>> bad;
      for (size_t e = 0; e < T.size(); ++e) {
        const double d = min_dihedral(mesh.V, T[e]);
        if (d < o.dihedral_target_deg) bad.emplace_back(d, static_cast<int>(e));
      }
      std::sort(bad.begin(), bad.end());
      int moved_now = 0;
      for (const auto& [d0, e] : bad) {
        const Tet& t = T[static_cast<size_t>(e)];
        if (min_dihedral(mesh.V, t) >= o.dihedral_target_deg) continue;
        int best_i = -1;
        double best_gain = 0, best_dv = 0;
        Eigen::Vector3d best_to = Eigen::Vector3d::Zero();
        for (int i : t) {
          const bool surf = L.surface[static_cast<size_t>(i)] != 0;
          const Eigen::Vector3d x = mesh.V.row(i).transpose();
          const double now = star_min(i, x);
          double mean_edge = 0;
          const std::set<int> nbrs = neighbours(L, i);
          for (int v : nbrs) mean_edge += (mesh.V.row(v) - mesh.V.row(i)).norm();
          if (nbrs.empty()) continue;
          mean_edge /= static_cast<double>(nbrs.size());
          std::vector<Eigen::Vector3d> cand;
          Eigen::Vector3d g = Eigen::Vector3d::Zero();
          const double h = 1e-4 * mean_edge;
          for (int k = 0; k < 3; ++k) {
            const Eigen::RowVector3d keep = mesh.V.row(i);
            mesh.V(i, k) += h;
            const double up = min_dihedral(mesh.V, t);
            mesh.V(i, k) -= 2 * h;
            const double down = min_dihedral(mesh.V, t);
            mesh.V.row(i) = keep;
            g[k] = (up - down) / (2 * h);
          }
          if (g.norm() > 0)
            for (double s : {0.01, 0.02, 0.04, 0.08, 0.16})
              cand.push_back(x + s * mean_edge * g.normalized());
          if (surf) {  // along the normal of the boundary around i, both ways
            Eigen::Vector3d nrm = Eigen::Vector3d::Zero();
            for (Eigen::Index f = 0; f < Fb.rows(); ++f)
              if (Fb(f, 0) == i || Fb(f, 1) == i || Fb(f, 2) == i) {
                const Eigen::Vector3d a = V1.row(Fb(f, 0)), b = V1.row(Fb(f, 1)), c = V1.row(Fb(f, 2));
                nrm += (b - a).cross(c - a);
              }
            if (nrm.norm() > 0)
              for (double s : {0.25, 0.5, 1.0}) {
                cand.push_back(x + s * budget * nrm.normalized());
                cand.push_back(x - s * budget * nrm.normalized());
              }
          }
          for (const Eigen::Vector3d& p : cand) {
            if (surf && off_boundary(p) > budget) continue;
            const double d = star_min(i, p);
            if (!(d > now + 1e-9) || d - now <= best_gain) continue;
            const TrialMove m = trial_move(mesh.V, T, L.around[static_cast<size_t>(i)], i, p, o.poisson);
            if (m.max_frequency > cap || !volume_ok(volume + m.volume_change)) continue;
            best_i = i;
            best_gain = d - now;
            best_to = p;
            best_dv = m.volume_change;
          }
        }
        if (best_i < 0) continue;
        mesh.V.row(best_i) = best_to.transpose();
        volume += best_dv;
        ++rep.off_surface;
        ++moved_now;
      }
      if (moved_now == 0) break;
    }
    if (rep.off_surface > 0) {
      w = node_frequencies(mesh.V, T, o.poisson);
      topological_phase();
    }
  }
  rep.min_dihedral_after = 180;
  for (const Tet& t : T) rep.min_dihedral_after = std::min(rep.min_dihedral_after, min_dihedral(mesh.V, t));
  for (int v = 0; v < n; ++v)
    if (w[v] > threshold) ++rep.stuck;
  rep.ratio_after = ideal / w.maxCoeff();
  rep.volume_change = volume / volume0 - 1;
  if (rep.collapses + rep.dihedral_collapses + rep.flips + rep.drops == 0)
    return rep;  // mesh.V holds the relocations
  // Compact: drop unused nodes, keep the order of the others.
  std::vector<int> id(static_cast<size_t>(n), -1);
  for (const Tet& t : T)
    for (int v : t) id[static_cast<size_t>(v)] = 0;
  int next = 0;
  for (int v = 0; v < n; ++v)
    if (id[static_cast<size_t>(v)] == 0) id[static_cast<size_t>(v)] = next++;
  MatX3d V(next, 3);
  for (int v = 0; v < n; ++v)
    if (id[static_cast<size_t>(v)] >= 0) V.row(id[static_cast<size_t>(v)]) = mesh.V.row(v);
  MatX4i Tn(static_cast<Eigen::Index>(T.size()), 4);
  for (size_t e = 0; e < T.size(); ++e)
    for (int k = 0; k < 4; ++k) Tn(static_cast<Eigen::Index>(e), k) = id[static_cast<size_t>(T[e][k])];
  mesh.V = std::move(V);
  mesh.T = std::move(Tn);
  mesh.F = boundary_faces(mesh.T);
  return rep;
}

}  // namespace icd::mesh
