#include <icd/fem/mass_scaling.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>

#include <icd/fem/model.hpp>
#include <icd/fem/stable_step.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::fem {

void validate(const MassScaling& o) {
  if (!(o.target_ratio >= 0) || !(o.target_ratio <= 1))
    throw ParameterError("fem::MassScaling: target_ratio = " + std::to_string(o.target_ratio) +
                         " is invalid: expected 0 (off) or a ratio in (0, 1]");
  if (!(o.max_added_fraction > 0) || !(o.max_added_fraction <= 1))
    throw ParameterError("fem::MassScaling: max_added_fraction = " +
                         std::to_string(o.max_added_fraction) + " is invalid: expected (0, 1]");
  if (o.max_passes < 1)
    throw ParameterError("fem::MassScaling: max_passes = " + std::to_string(o.max_passes) +
                         " is invalid: expected >= 1");
}

std::string MassScalingReport::shortfall() const {
  if (reached || target_ratio == 0) return "";
  if (scaled_nodes == 0 && !pass_limited)
    return " (target not reached: its first pass exceeds the added-mass limit)";
  if (pass_limited)
    return " (target not reached: it ran out of passes (" + std::to_string(passes) +
           ", MassScaling::max_passes) below the added-mass limit)";
  return " (target not reached: the next pass would exceed the added-mass limit)";
}

std::string MassScalingReport::to_string() const {
  if (target_ratio == 0) return "mass scaling off";
  char buf[320];
  if (scaled_nodes == 0) {
    std::snprintf(buf, sizeof buf, "mass scaling to %.2g: nothing added%s, step ratio %.3f",
                  target_ratio, shortfall().c_str(), ratio_before);
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "mass scaling to %.2g: +%.3g %% mass on %d nodes (max x %.3g), step ratio %.3f -> "
                "%.3f%s",
                target_ratio, 100.0 * added_fraction, scaled_nodes, max_factor, ratio_before,
                ratio_after, shortfall().c_str());
  return buf;
}

void bcc_block(int n, double h, MatX3d& V, MatX4i& T) {
  if (n < 2 || !(h > 0.0) || !std::isfinite(h))
    throw ParameterError("bcc_block: need n >= 2 cells and a finite edge h > 0 (got n = " +
                         std::to_string(n) + ", h = " + std::to_string(h) + ")");
  std::map<std::array<int, 3>, int> id;  // doubled integer coordinates -> node
  std::vector<Eigen::RowVector3d> pts;
  const auto node = [&](int x, int y, int z) {
    auto [it, inserted] = id.try_emplace({x, y, z}, static_cast<int>(pts.size()));
    if (inserted) pts.emplace_back(0.5 * h * x, 0.5 * h * y, 0.5 * h * z);
    return it->second;
  };
  std::vector<std::array<int, 4>> tets;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int i = 0; i + 1 < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          // Centres of cells (i, j, k) and (i + 1, j, k) along `axis`, doubled.
          std::array<int, 3> c1{}, c2{};
          c1[axis] = 2 * i + 1, c2[axis] = 2 * i + 3;
          c1[u] = c2[u] = 2 * j + 1;
          c1[v] = c2[v] = 2 * k + 1;
          // Corners of the face between them, in order around it.
          std::array<std::array<int, 3>, 4> q{};
          static constexpr int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
          for (int m = 0; m < 4; ++m) {
            q[m][axis] = 2 * i + 2;
            q[m][u] = 2 * (j + du[m]);
            q[m][v] = 2 * (k + dv[m]);
          }
          const int a = node(c1[0], c1[1], c1[2]), b = node(c2[0], c2[1], c2[2]);
          for (int m = 0; m < 4; ++m) {
            const auto &p = q[m], &r = q[(m + 1) % 4];
            tets.push_back({a, b, node(p[0], p[1], p[2]), node(r[0], r[1], r[2])});
          }
        }
  }
  V.resize(static_cast<Eigen::Index>(pts.size()), 3);
  for (size_t i = 0; i < pts.size(); ++i) V.row(static_cast<Eigen::Index>(i)) = pts[i];
  T.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (size_t t = 0; t < tets.size(); ++t) {
    auto e = tets[t];
    const Eigen::Vector3d p0 = V.row(e[0]), p1 = V.row(e[1]), p2 = V.row(e[2]), p3 = V.row(e[3]);
    if ((p1 - p0).dot((p2 - p0).cross(p3 - p0)) < 0) std::swap(e[2], e[3]);
    for (int c = 0; c < 4; ++c) T(static_cast<Eigen::Index>(t), c) = e[c];
  }
}

namespace {

// The Lanczos bound used for every figure here: the settings of
// mesh/pipeline/fem_step.cpp (graded meshes need more than the Simulator's
// first 60 iterations for a converged figure).
FrequencyEstimate rest_estimate(Model& model, const Eigen::Ref<const MatX3d>& x) {
  FrequencyOptions fo;
  fo.max_iterations = 400;
  return estimate_max_frequency(model, x, fo);
}

}  // namespace

double ideal_max_frequency(const Material& material, double mean_volume) {
  validate(material);
  if (!(mean_volume > 0) || !std::isfinite(mean_volume))
    throw ParameterError("fem::ideal_max_frequency: mean_volume = " + std::to_string(mean_volume) +
                         " must be finite and > 0");
  static std::mutex mutex;
  static std::map<std::pair<int, double>, double> unit;  // (model, nu) -> omega at E = rho = V = 1
  const std::pair<int, double> key{static_cast<int>(material.model), material.poisson};
  double w = 0;
  {
    std::lock_guard<std::mutex> lock(mutex);
    const auto it = unit.find(key);
    if (it != unit.end()) w = it->second;
  }
  if (w == 0) {
    Material m = material;
    m.young = 1;
    m.density = 1;
    MatX3d V;
    MatX4i T;
    bcc_block(5, std::cbrt(12.0), V, T);  // tets of volume 1
    Model model(V, T, m);
    w = rest_estimate(model, V).omega_bound;
    std::lock_guard<std::mutex> lock(mutex);
    unit.emplace(key, w);
  }
  return w * std::sqrt(material.young / material.density) / std::cbrt(mean_volume);
}

Eigen::VectorXd node_stiffness(Model& model, const Eigen::Ref<const MatX3d>& x) {
  const Eigen::SparseMatrix<double>& K = model.elastic().stiffness(x);
  const int n = model.num_nodes();
  std::vector<Eigen::Matrix3d> block(static_cast<size_t>(n), Eigen::Matrix3d::Zero());
  for (int col = 0; col < K.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it)
      if (it.row() / 3 == col / 3)
        block[static_cast<size_t>(col / 3)](it.row() % 3, col % 3) = it.value();
  Eigen::VectorXd lambda(n);
  for (int i = 0; i < n; ++i) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(block[static_cast<size_t>(i)],
                                                      Eigen::EigenvaluesOnly);
    lambda[i] = std::max(0.0, es.eigenvalues()[2]);
  }
  return lambda;
}

MassScalingReport apply_mass_scaling(Model& model, const Eigen::Ref<const MatX3d>& rest,
                                     const MassScaling& o) {
  validate(o);
  MassScalingReport r;
  r.target_ratio = o.target_ratio;
  if (o.target_ratio == 0) return r;
  const Eigen::VectorXd m0 = model.mass();
  const double total = m0.sum();
  r.ideal_omega = ideal_max_frequency(model.material(), model.mesh().rest_volume.mean());
  const double target = r.ideal_omega / o.target_ratio;
  r.omega_before = r.omega_after = rest_estimate(model, rest).omega_bound;
  r.estimates = 1;
  r.ratio_before = r.ratio_after = r.ideal_omega / r.omega_before;
  if (r.omega_before <= target) {
    r.reached = true;
    return r;
  }
  const Eigen::VectorXd lambda = node_stiffness(model, rest);
  double threshold = target;
  Eigen::VectorXd kept = m0;  // the last masses within the added-mass limit
  const auto masses_at = [&](double th) {
    Eigen::VectorXd m = m0;
    for (Eigen::Index i = 0; i < m.size(); ++i)
      if (m0[i] > 0) m[i] = std::max(m0[i], lambda[i] / (th * th));
    return m;
  };
  const auto over_limit = [&](const Eigen::VectorXd& m) {
    return m.sum() - total > o.max_added_fraction * total;
  };
  double prev_threshold = 0, prev_omega = 0;
  double missed = 0;     // the last threshold whose pass did not reach the target
  bool at_limit = false;  // this pass's threshold puts the added mass at the limit
  for (;;) {
    if (r.passes == o.max_passes) {
      r.pass_limited = true;
      break;
    }
    Eigen::VectorXd m = masses_at(threshold);
    if (over_limit(m)) {
      // A pass that would exceed the limit after one within it: the threshold
      // between the two whose added mass is the limit (the mass falls
      // monotonically with the threshold), one more pass there. Without it a
      // large step (s small) stopped the scaling with most of its budget
      // unused (the corpus' refined_elephant: +0.22 % of 5 %, ratio 0.32).
      if (r.node_omega == 0 || at_limit) {
        r.mass_limited = true;
        break;
      }
      double lo = threshold, hi = r.node_omega;  // over the limit, within it
      for (int k = 0; k < 40 && hi > lo * (1 + 1e-9); ++k) {
        const double mid = std::sqrt(lo * hi);
        (over_limit(masses_at(mid)) ? lo : hi) = mid;
      }
      threshold = hi;
      at_limit = true;
      m = masses_at(threshold);
    }
    model.set_masses(m);
    kept = m;
    ++r.passes;
    r.node_omega = threshold;
    r.omega_after = rest_estimate(model, rest).omega_bound;
    ++r.estimates;
    if (r.omega_after <= target) break;
    missed = threshold;
    // The top modes of the scaled model sit on its light nodes: their
    // frequency moves with the threshold, omega ~ threshold^s with s <= 1
    // (coupled nodes: less), measured from the last two passes; 0.999: not to
    // stop just above. With s = 1 always (as before) the elephant and part
    // of the corpus crept to 0.3999 and 0.397 in 8 passes.
    double s = 1;
    if (prev_threshold > 0 && prev_omega > r.omega_after && prev_threshold > threshold)
      s = std::clamp(std::log(prev_omega / r.omega_after) / std::log(prev_threshold / threshold),
                     0.25, 1.0);
    prev_threshold = threshold;
    prev_omega = r.omega_after;
    threshold *= std::pow(0.999 * target / r.omega_after, 1.0 / s);
  }
  // Past the target by more than 1 % (the top mode moved to other nodes):
  // bisect between the last threshold that missed and the one that reached,
  // for the least mass that reaches it (within the pass limit).
  if (r.omega_after <= target && missed > threshold) {
    double lo = threshold, hi = missed, lo_omega = r.omega_after;
    for (int k = 0; k < 6 && r.passes < o.max_passes && target > 1.01 * lo_omega; ++k) {
      const double mid = std::sqrt(lo * hi);
      model.set_masses(masses_at(mid));
      ++r.passes;
      ++r.estimates;
      const double w = rest_estimate(model, rest).omega_bound;
      if (w <= target) {
        lo = mid;
        lo_omega = w;
      } else {
        hi = mid;
      }
    }
    kept = masses_at(lo);
    model.set_masses(kept);
    r.node_omega = lo;
    r.omega_after = lo_omega;
  }
  if (r.node_omega == 0) {  // even the first pass would exceed the limit: nothing added
    model.set_masses(m0);
    return r;
  }
  r.ratio_after = r.ideal_omega / r.omega_after;
  r.reached = r.omega_after <= target;
  for (Eigen::Index i = 0; i < m0.size(); ++i)
    if (kept[i] > m0[i]) {
      ++r.scaled_nodes;
      r.max_factor = std::max(r.max_factor, kept[i] / m0[i]);
    }
  r.added_mass = kept.sum() - total;
  r.added_fraction = r.added_mass / total;
  return r;
}

}  // namespace icd::fem
