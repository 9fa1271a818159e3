#include <icd/coupling/contact_response.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/union_find.hpp>

namespace icd::coupling {
namespace {

using collision::NodePair;
using collision::SphereTree;

void check_node(int32_t n, Eigen::Index num_nodes, const char* which) {
  if (n < 0 || n >= num_nodes)
    throw ParameterError(std::string("contact response: tree ") + which +
                         " refers to coarse node " + std::to_string(n) + " but the object has " +
                         std::to_string(num_nodes));
}

// The tree's sphere-to-node association: every node of the whole tree, or
// with a result only those of the spheres its pairs name on this side (the
// per-cycle calls: O(pairs), not O(tree)), and those spheres exist.
void check_association(const SphereTree& t, Eigen::Index num_nodes, const char* which,
                       const collision::CollisionResult* result = nullptr) {
  if (t.assoc_offset.size() != t.spheres.size() + 1)
    throw ParameterError(std::string("contact response: tree ") + which +
                         " has no sphere-to-node association");
  if (!result) {
    for (int32_t n : t.assoc_nodes) check_node(n, num_nodes, which);
    return;
  }
  const bool side_a = which[0] == 'a';
  const auto check = [&](const std::vector<NodePair>& pairs) {
    for (const NodePair& p : pairs) {
      const int32_t s = side_a ? p.a : p.b;
      if (s < 0 || static_cast<size_t>(s) >= t.spheres.size())
        throw ParameterError(std::string("contact response: a pair names sphere ") +
                             std::to_string(s) + " of tree " + which + ", which has " +
                             std::to_string(t.spheres.size()));
      for (int32_t j = t.assoc_offset[s]; j < t.assoc_offset[s + 1]; ++j)
        check_node(t.assoc_nodes[j], num_nodes, which);
    }
  };
  check(result->colliding);
  check(result->untested);
}

// Per-object accumulator: forces per node and, for PaperAverage, counts.
struct Accumulator {
  Eigen::Ref<MatX3d> out;
  const SphereTree& tree;
  ContactDistribution mode;
  std::vector<int> count;     // PaperAverage: forces received per node
  MatX3d received;            // PaperAverage: sum of received forces
  Eigen::VectorXd stiffness;  // added stiffness per node

  const Eigen::VectorXd* mass;  // node masses, or null
  Eigen::VectorXd rate;         // per node: sum of k * share / m_n (1/s^2)

  Accumulator(Eigen::Ref<MatX3d> o, const SphereTree& t, ContactDistribution m,
              const Eigen::VectorXd* node_mass)
      : out(o),
        tree(t),
        mode(m),
        stiffness(Eigen::VectorXd::Zero(o.rows())),
        mass(node_mass),
        rate(Eigen::VectorXd::Zero(node_mass ? o.rows() : 0)) {
    if (mode == ContactDistribution::PaperAverage) {
      count.assign(static_cast<size_t>(o.rows()), 0);
      received = MatX3d::Zero(o.rows(), 3);
    }
  }

  void add(int sphere, const Eigen::Vector3d& f, double k) {
    const int32_t begin = tree.assoc_offset[sphere], end = tree.assoc_offset[sphere + 1];
    double share = 1.0 / std::max(1, end - begin);
    double total_mass = 0;
    if (mode == ContactDistribution::MassWeighted)
      for (int32_t j = begin; j < end; ++j) total_mass += (*mass)[tree.assoc_nodes[j]];
    for (int32_t j = begin; j < end; ++j) {
      const int32_t node = tree.assoc_nodes[j];
      if (mode == ContactDistribution::MassWeighted) share = (*mass)[node] / total_mass;
      if (mass)
        rate[node] += k * (mode == ContactDistribution::PaperAverage ? 1.0 : share) / (*mass)[node];
      if (mode != ContactDistribution::PaperAverage) {
        out.row(node) += share * f.transpose();
        stiffness[node] += share * k;
      } else {
        received.row(node) += f.transpose();
        ++count[node];
        stiffness[node] += k;
      }
    }
  }

  Eigen::Vector3d finish() {
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    if (mode == ContactDistribution::PaperAverage) {
      for (Eigen::Index n = 0; n < out.rows(); ++n)
        if (count[n] > 0) {
          const Eigen::RowVector3d avg = received.row(n) / count[n];
          out.row(n) += avg;
          total += avg.transpose();
          stiffness[n] /= count[n];
          if (mass) rate[n] /= count[n];
        }
    }
    return total;
  }
};

// Adds k * share_n / m_n of sphere `sphere` to rate[n] for its nodes n (the
// rate Accumulator::add reports), PartitionOfUnity or MassWeighted.
void add_rate(const SphereTree& t, const Eigen::VectorXd& mass, ContactDistribution mode,
              int sphere, double k, Eigen::VectorXd& rate) {
  const int32_t begin = t.assoc_offset[sphere], end = t.assoc_offset[sphere + 1];
  double total_mass = 0;
  if (mode == ContactDistribution::MassWeighted)
    for (int32_t j = begin; j < end; ++j) total_mass += mass[t.assoc_nodes[j]];
  for (int32_t j = begin; j < end; ++j) {
    const int32_t node = t.assoc_nodes[j];
    const double share =
        mode == ContactDistribution::MassWeighted ? mass[node] / total_mass : 1.0 / (end - begin);
    rate[node] += k * share / mass[node];
  }
}

// min over the nodes of `sphere` of cap / rate[n].
double weight_of(const SphereTree& t, int sphere, const Eigen::VectorXd& rate, double cap) {
  double w = std::numeric_limits<double>::infinity();
  for (int32_t j = t.assoc_offset[sphere]; j < t.assoc_offset[sphere + 1]; ++j) {
    const double r = rate[t.assoc_nodes[j]];
    if (r > 0) w = std::min(w, cap / r);
  }
  return w;
}

}  // namespace

Eigen::SparseMatrix<double> sphere_to_node_matrix(const SphereTree& tree, int num_coarse_nodes) {
  check_association(tree, num_coarse_nodes, "");
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(tree.assoc_nodes.size());
  for (int i = 0; i < tree.num_nodes(); ++i) {
    const int32_t begin = tree.assoc_offset[i], end = tree.assoc_offset[i + 1];
    for (int32_t j = begin; j < end; ++j)
      trip.emplace_back(tree.assoc_nodes[j], i, 1.0 / (end - begin));
  }
  Eigen::SparseMatrix<double> D(num_coarse_nodes, tree.num_nodes());
  D.setFromTriplets(trip.begin(), trip.end());
  return D;
}

void add_contact_rates(const SphereTree& a, const SphereTree& b,
                       const collision::CollisionResult& result, const ContactOptions& options,
                       Eigen::VectorXd& rate_a, Eigen::VectorXd& rate_b) {
  if (!options.mass_a || !options.mass_b)
    throw ParameterError("contact response: node rates need mass_a and mass_b");
  check_association(a, options.mass_a->size(), "a", &result);
  check_association(b, options.mass_b->size(), "b", &result);
  if (rate_a.size() != options.mass_a->size() || rate_b.size() != options.mass_b->size())
    throw ParameterError("contact response: one rate per coarse node needed");
  const double k = options.stiffness;
  auto load = [&](const NodePair& p, double cap) {
    const collision::Sphere& sa = a.spheres[p.a];
    const collision::Sphere& sb = b.spheres[p.b];
    if (!(std::min(sa.r + sb.r - (sb.center() - sa.center()).norm(), cap) > 0.0)) return;
    add_rate(a, *options.mass_a, options.distribution, p.a, k, rate_a);
    add_rate(b, *options.mass_b, options.distribution, p.b, k, rate_b);
  };
  for (const NodePair& p : result.colliding) load(p, std::numeric_limits<double>::infinity());
  if (options.use_untested)
    for (const NodePair& p : result.untested) load(p, options.max_untested_penetration);
}

ContactStats apply_contact_forces(const SphereTree& a, const SphereTree& b,
                                  const collision::CollisionResult& result,
                                  const ContactOptions& options, Eigen::Ref<MatX3d> forces_a,
                                  Eigen::Ref<MatX3d> forces_b) {
  if (!(options.stiffness > 0.0) || !std::isfinite(options.stiffness))
    throw ParameterError("contact response: stiffness must be positive and finite (got " +
                         std::to_string(options.stiffness) + ")");
  check_association(a, forces_a.rows(), "a", &result);
  check_association(b, forces_b.rows(), "b", &result);
  auto check_mass = [](const Eigen::VectorXd* m, Eigen::Index rows, const char* which) {
    if (!m) return;
    if (m->size() != rows || !(m->minCoeff() > 0.0) || !m->allFinite())
      throw ParameterError(std::string("contact response: mass_") + which + " must hold " +
                           std::to_string(rows) + " positive finite node masses");
  };
  check_mass(options.mass_a, forces_a.rows(), "a");
  check_mass(options.mass_b, forces_b.rows(), "b");
  if (options.distribution == ContactDistribution::MassWeighted &&
      (!options.mass_a || !options.mass_b))
    throw ParameterError(
        "contact response: the mass-weighted distribution needs mass_a and mass_b");
  Eigen::Vector3d fallback = options.coincident_direction;
  fallback = fallback.allFinite() && fallback.norm() > 0 ? fallback.normalized()
                                                         : Eigen::Vector3d::UnitZ();

  const double rate_cap = options.node_rate_limit;
  if (!(rate_cap > 0.0))
    throw ParameterError("contact response: node_rate_limit must be positive (got " +
                         std::to_string(rate_cap) + ")");
  const bool capped =
      std::isfinite(rate_cap) && options.distribution != ContactDistribution::PaperAverage;
  if (capped && (!options.mass_a || !options.mass_b))
    throw ParameterError("contact response: node_rate_limit needs mass_a and mass_b");

  Accumulator acc_a(forces_a, a, options.distribution, options.mass_a),
      acc_b(forces_b, b, options.distribution, options.mass_b);
  ContactStats stats;
  const double k = options.stiffness;
  if (!(options.max_untested_penetration > 0.0))
    throw ParameterError("contact response: max_untested_penetration must be positive (got " +
                         std::to_string(options.max_untested_penetration) + ")");
  // With a node rate cap: first every node's rate at the full k (given, over
  // all object pairs, or of this call's pairs), then each pair weighted by
  // the most loaded node of its two spheres.
  Eigen::VectorXd own_a, own_b;
  const Eigen::VectorXd* rate_a = options.total_rate_a;
  const Eigen::VectorXd* rate_b = options.total_rate_b;
  if (capped) {
    if ((rate_a && rate_a->size() != forces_a.rows()) || (rate_b && rate_b->size() != forces_b.rows()))
      throw ParameterError("contact response: total_rate_a / total_rate_b must hold one rate per coarse node");
    if (!rate_a || !rate_b) {
      own_a = Eigen::VectorXd::Zero(forces_a.rows());
      own_b = Eigen::VectorXd::Zero(forces_b.rows());
      add_contact_rates(a, b, result, options, own_a, own_b);
      rate_a = &own_a;
      rate_b = &own_b;
    }
  }
  auto respond = [&](const NodePair& p, double cap, bool leaf) {
    const collision::Sphere& sa = a.spheres[p.a];
    const collision::Sphere& sb = b.spheres[p.b];
    const Eigen::Vector3d d = sb.center() - sa.center();
    const double dist = d.norm();
    const double delta = std::min(sa.r + sb.r - dist, cap);
    if (!(delta > 0.0)) return;
    const Eigen::Vector3d n = dist > 1e-12 * (sa.r + sb.r) ? Eigen::Vector3d(d / dist) : fallback;
    double kp = k;
    if (capped) {
      double w = std::min(weight_of(a, p.a, *rate_a, rate_cap), weight_of(b, p.b, *rate_b, rate_cap));
      if (!std::isfinite(w)) w = 1;
      w = std::min(w, 1.0);
      if (w < 1) {
        ++stats.capped_pairs;
        stats.min_weight = std::min(stats.min_weight, w);
      }
      kp = w * k;
    }
    const Eigen::Vector3d f = kp * delta * n;  // on b; -f on a (Eq. 11)
    acc_a.add(p.a, -f, kp);
    acc_b.add(p.b, f, kp);
    if (options.distribution != ContactDistribution::PaperAverage) {
      stats.total_force_a -= f;
      stats.total_force_b += f;
    }
    ++stats.active_pairs;
    stats.max_penetration = std::max(stats.max_penetration, delta);
    stats.penalty_energy += 0.5 * kp * delta * delta;
    if (leaf) {
      const double ratio = delta / std::max(std::min(sa.r, sb.r), 1e-300);
      stats.max_depth_ratio = std::max(stats.max_depth_ratio, ratio);
      stats.deep_pairs += ratio > 1.0;
    }
  };
  for (const NodePair& p : result.colliding) respond(p, std::numeric_limits<double>::infinity(), true);
  if (options.use_untested)
    for (const NodePair& p : result.untested) respond(p, options.max_untested_penetration, false);
  if (options.distribution == ContactDistribution::PaperAverage) {
    stats.total_force_a = acc_a.finish();
    stats.total_force_b = acc_b.finish();
  }
  if (options.mass_a && options.mass_b && stats.active_pairs > 0) {
    stats.max_rate = acc_a.rate.maxCoeff() + acc_b.rate.maxCoeff();
    if (options.applied_rate_a && options.applied_rate_a->size() == acc_a.rate.size())
      *options.applied_rate_a += acc_a.rate;
    if (options.applied_rate_b && options.applied_rate_b->size() == acc_b.rate.size())
      *options.applied_rate_b += acc_b.rate;
  }
  stats.max_node_stiffness = std::max(acc_a.stiffness.size() ? acc_a.stiffness.maxCoeff() : 0.0,
                                      acc_b.stiffness.size() ? acc_b.stiffness.maxCoeff() : 0.0);
  return stats;
}

DeepContactStats deep_contact_velocity_step(const SphereTree& a, const SphereTree& b,
                                            const collision::CollisionResult& result,
                                            const Eigen::VectorXd& mass_a,
                                            const Eigen::VectorXd& mass_b, Eigen::Ref<MatX3d> vel_a,
                                            Eigen::Ref<MatX3d> vel_b, double depth_ratio) {
  check_association(a, vel_a.rows(), "a", &result);
  check_association(b, vel_b.rows(), "b", &result);
  if (mass_a.size() != vel_a.rows() || mass_b.size() != vel_b.rows() ||
      !(mass_a.minCoeff() > 0.0) || !(mass_b.minCoeff() > 0.0))
    throw ParameterError("deep contact step: one positive mass per node and object needed");
  DeepContactStats stats;
  // The deep pairs, their normals and their spheres' node masses.
  struct Deep {
    NodePair p;
    Eigen::Vector3d n;
    double ma, mb;
    bool active;   // approaching in this sweep
    bool stepped;  // its velocities changed in some sweep
  };
  std::vector<Deep> deep;
  for (const NodePair& p : result.colliding) {
    const collision::Sphere& sa = a.spheres[p.a];
    const collision::Sphere& sb = b.spheres[p.b];
    const Eigen::Vector3d d = sb.center() - sa.center();
    const double dist = d.norm();
    const double delta = sa.r + sb.r - dist;
    if (!(delta > depth_ratio * std::min(sa.r, sb.r)) || !(dist > 1e-12 * (sa.r + sb.r))) continue;
    if (a.assoc_offset[p.a] == a.assoc_offset[p.a + 1] ||
        b.assoc_offset[p.b] == b.assoc_offset[p.b + 1])
      continue;
    double ma = 0, mb = 0;
    for (int32_t k = a.assoc_offset[p.a]; k < a.assoc_offset[p.a + 1]; ++k) ma += mass_a[a.assoc_nodes[k]];
    for (int32_t k = b.assoc_offset[p.b]; k < b.assoc_offset[p.b + 1]; ++k) mb += mass_b[b.assoc_nodes[k]];
    deep.push_back({p, d / dist, ma, mb, false, false});
  }
  stats.pairs = static_cast<int>(deep.size());
  if (deep.empty()) return stats;
  // Mass-weighted mean velocity of a sphere's nodes.
  auto mean = [](const SphereTree& t, int s, const Eigen::VectorXd& m, const auto& v, double total) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int32_t j = t.assoc_offset[s]; j < t.assoc_offset[s + 1]; ++j)
      p += m[t.assoc_nodes[j]] * v.row(t.assoc_nodes[j]).transpose();
    return Eigen::Vector3d(p / total);
  };
  const auto na = static_cast<int32_t>(vel_a.rows()), nb = static_cast<int32_t>(vel_b.rows());
  MatX3d impulse(na + nb, 3);  // per node of a, then of b
  // Nodes of a and b (b's numbered from na): those of the pairs still
  // approaching (touched), grouped into patches by the nodes they share.
  UnionFind shared(na + nb);
  std::vector<char> touched(static_cast<size_t>(na + nb));
  std::vector<int32_t> patch_of(touched.size());
  struct Patch {
    double g = 0, h = 0, scale = 0;
  };
  std::vector<Patch> patches;
  auto join = [&](int32_t x, int32_t y) {
    touched[x] = touched[y] = 1;
    shared.unite(x, y);
  };
  auto node_mass = [&](int32_t x) { return x < na ? mass_a[x] : mass_b[x - na]; };
  auto node_vel = [&](int32_t x) {
    return x < na ? Eigen::RowVector3d(vel_a.row(x)) : Eigen::RowVector3d(vel_b.row(x - na));
  };
  // Sweeps, each judging every deep pair on the same velocities (no order):
  // each pair still approaching gets the impulse j n (on b; -j n on a,
  // j = mu v_n) that would stop it alone, spread over its spheres' nodes in
  // proportion to their masses (each node of a sphere shifted by the same
  // velocity). Pairs that share a coarse node (of either object) form a
  // patch; overlapping on its nodes, its pairs' impulses all at once would
  // overshoot, so they are applied together scaled by s = min(1, -G / H),
  // G = sum impulse . v and H = sum |impulse|^2 / m over the patch's nodes:
  // the kinetic energy changes by s G + s^2 H / 2 <= 0 (at s = -G / H the
  // most the scaled impulses can remove); a lone pair gets s = 1, its
  // approach stopped. Patches share no node. Repeated until no deep pair
  // approaches (up to kSweeps; the first sweep nearly always settles a lone
  // pair, overlapping ones converge like a Jacobi iteration).
  constexpr int kSweeps = 32;
  const double tiny = 1e-12;
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    impulse.setZero();
    shared.reset(na + nb);
    std::fill(touched.begin(), touched.end(), 0);
    std::fill(patch_of.begin(), patch_of.end(), -1);
    bool any = false;
    for (Deep& q : deep) {
      q.active = false;
      const Eigen::Vector3d va = mean(a, q.p.a, mass_a, vel_a, q.ma);
      const Eigen::Vector3d vb = mean(b, q.p.b, mass_b, vel_b, q.mb);
      const double vn = (vb - va).dot(q.n);  // < 0: approaching
      // (a relative bound: rounding leaves pairs stopped by the last sweep
      // at |v_n| ~ 1e-16 |v|)
      if (!(vn < -tiny * (va.norm() + vb.norm()))) continue;
      any = q.active = true;
      const double j = -vn * q.ma * q.mb / (q.ma + q.mb);
      const int32_t first = a.assoc_nodes[a.assoc_offset[q.p.a]];
      for (int32_t k = a.assoc_offset[q.p.a]; k < a.assoc_offset[q.p.a + 1]; ++k) {
        const int32_t node = a.assoc_nodes[k];
        impulse.row(node) -= (mass_a[node] / q.ma * j) * q.n.transpose();
        join(first, node);
      }
      for (int32_t k = b.assoc_offset[q.p.b]; k < b.assoc_offset[q.p.b + 1]; ++k) {
        const int32_t node = b.assoc_nodes[k];
        impulse.row(na + node) += (mass_b[node] / q.mb * j) * q.n.transpose();
        join(first, na + node);
      }
    }
    if (!any) break;
    patches.clear();
    for (int32_t x = 0; x < na + nb; ++x) {
      if (!touched[x]) continue;
      const int32_t root = shared.find(x);
      if (patch_of[root] < 0) {
        patch_of[root] = static_cast<int32_t>(patches.size());
        patches.emplace_back();
      }
      patch_of[x] = patch_of[root];
      Patch& pt = patches[patch_of[x]];
      pt.g += impulse.row(x).dot(node_vel(x));
      pt.h += impulse.row(x).squaredNorm() / node_mass(x);
    }
    bool moved = false;
    for (Patch& pt : patches) {
      pt.scale = 0;
      if (!(pt.g < 0.0) || !(pt.h > 0.0)) continue;  // together they do not oppose the motion
      pt.scale = std::min(1.0, -pt.g / pt.h);
      stats.removed_energy -= pt.scale * pt.g + 0.5 * pt.scale * pt.scale * pt.h;
      moved = true;
    }
    if (!moved) break;
    for (Deep& q : deep)
      if (q.active && patches[patch_of[a.assoc_nodes[a.assoc_offset[q.p.a]]]].scale > 0)
        q.stepped = true;
    for (int32_t x = 0; x < na + nb; ++x) {
      if (patch_of[x] < 0 || patches[patch_of[x]].scale == 0.0) continue;
      const Eigen::RowVector3d dv = (patches[patch_of[x]].scale / node_mass(x)) * impulse.row(x);
      if (x < na)
        vel_a.row(x) += dv;
      else
        vel_b.row(x - na) += dv;
    }
  }
  for (const Deep& q : deep) stats.approaching += q.stepped;
  return stats;
}

}  // namespace icd::coupling
