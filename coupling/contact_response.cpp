#include <icd/coupling/contact_response.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

using collision::NodePair;
using collision::SphereTree;

void check_association(const SphereTree& t, Eigen::Index num_nodes, const char* which) {
  if (t.assoc_offset.size() != t.spheres.size() + 1)
    throw ParameterError(std::string("contact response: tree ") + which +
                         " has no sphere-to-node association");
  for (int32_t n : t.assoc_nodes)
    if (n < 0 || n >= num_nodes)
      throw ParameterError(std::string("contact response: tree ") + which +
                           " refers to coarse node " + std::to_string(n) + " but the object has " +
                           std::to_string(num_nodes));
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

ContactStats apply_contact_forces(const SphereTree& a, const SphereTree& b,
                                  const collision::CollisionResult& result,
                                  const ContactOptions& options, Eigen::Ref<MatX3d> forces_a,
                                  Eigen::Ref<MatX3d> forces_b) {
  if (!(options.stiffness > 0.0) || !std::isfinite(options.stiffness))
    throw ParameterError("contact response: stiffness must be positive and finite (got " +
                         std::to_string(options.stiffness) + ")");
  check_association(a, forces_a.rows(), "a");
  check_association(b, forces_b.rows(), "b");
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

  Accumulator acc_a(forces_a, a, options.distribution, options.mass_a),
      acc_b(forces_b, b, options.distribution, options.mass_b);
  ContactStats stats;
  const double k = options.stiffness;
  auto respond = [&](const NodePair& p, double cap, bool leaf) {
    const collision::Sphere& sa = a.spheres[p.a];
    const collision::Sphere& sb = b.spheres[p.b];
    const Eigen::Vector3d d = sb.center() - sa.center();
    const double dist = d.norm();
    const double delta = std::min(sa.r + sb.r - dist, cap);
    if (!(delta > 0.0)) return;
    const Eigen::Vector3d n = dist > 1e-12 * (sa.r + sb.r) ? Eigen::Vector3d(d / dist) : fallback;
    const Eigen::Vector3d f = k * delta * n;  // on b; -f on a (Eq. 11)
    acc_a.add(p.a, -f, k);
    acc_b.add(p.b, f, k);
    if (options.distribution != ContactDistribution::PaperAverage) {
      stats.total_force_a -= f;
      stats.total_force_b += f;
    }
    ++stats.active_pairs;
    stats.max_penetration = std::max(stats.max_penetration, delta);
    stats.penalty_energy += 0.5 * k * delta * delta;
    if (leaf) {
      const double ratio = delta / std::max(std::min(sa.r, sb.r), 1e-300);
      stats.max_depth_ratio = std::max(stats.max_depth_ratio, ratio);
      stats.deep_pairs += ratio > 1.0;
    }
  };
  if (!(options.max_untested_penetration > 0.0))
    throw ParameterError("contact response: max_untested_penetration must be positive (got " +
                         std::to_string(options.max_untested_penetration) + ")");
  for (const NodePair& p : result.colliding) respond(p, std::numeric_limits<double>::infinity(), true);
  if (options.use_untested)
    for (const NodePair& p : result.untested) respond(p, options.max_untested_penetration, false);
  if (options.distribution == ContactDistribution::PaperAverage) {
    stats.total_force_a = acc_a.finish();
    stats.total_force_b = acc_b.finish();
  }
  if (options.mass_a && options.mass_b && stats.active_pairs > 0)
    stats.max_rate = acc_a.rate.maxCoeff() + acc_b.rate.maxCoeff();
  stats.max_node_stiffness = std::max(acc_a.stiffness.size() ? acc_a.stiffness.maxCoeff() : 0.0,
                                      acc_b.stiffness.size() ? acc_b.stiffness.maxCoeff() : 0.0);
  return stats;
}

}  // namespace icd::coupling
