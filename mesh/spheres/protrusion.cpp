#include <icd/mesh/spheres/protrusion.hpp>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include <icd/mesh/core/error.hpp>

namespace icd::mesh {
namespace {

void check_options(const ProtrusionPolishOptions& o) {
  if (o.search_directions < 1 || o.check_directions < 1 || o.max_evaluations < 0 ||
      !(o.initial_step > 0) || !(o.min_step > 0)) {
    throw ParameterError(
        "ProtrusionPolishOptions: search_directions and check_directions must be >= 1, "
        "max_evaluations >= 0, initial_step and min_step > 0");
  }
}

/// Protrusion of a moving sphere on fixed directions, with bounds carried
/// from move to move: the signed protrusion of a point (distance outside,
/// minus the distance inside) is 1-Lipschitz, and a probe moves by at most
/// |c' - c| + |r' - r|, so only probes whose bound exceeds the largest value
/// found so far are queried, in decreasing order of bound.
class ProbeSet {
 public:
  ProbeSet(const MeshOracle& oracle, MatX3d directions)
      : m_oracle(oracle), m_dirs(std::move(directions)) {}

  /// Makes (c, r) the incumbent; returns its exact protrusion.
  double reset(const Eigen::Vector3d& c, double r) {
    m_c = c, m_r = r;
    m_bound.assign(static_cast<size_t>(m_dirs.rows()), kUnknown);
    m_trial = m_bound;
    const double value = query(c, r, kUnknown);
    m_bound = m_trial;
    return value;
  }

  /// The protrusion at (c, r) when it is below `cutoff`; otherwise some
  /// value >= cutoff (the query stops early).
  double try_move(const Eigen::Vector3d& c, double r, double cutoff) {
    const double move = (c - m_c).norm() + std::abs(r - m_r);
    m_trial = m_bound;
    for (double& b : m_trial) b += move;
    return query(c, r, cutoff);
  }

  /// Makes the last try_move() the incumbent.
  void accept(const Eigen::Vector3d& c, double r) {
    m_c = c, m_r = r;
    m_bound = m_trial;
  }

 private:
  static constexpr double kUnknown = std::numeric_limits<double>::infinity();

  double query(const Eigen::Vector3d& c, double r, double cutoff) {
    m_order.resize(m_trial.size());
    for (size_t i = 0; i < m_order.size(); ++i) m_order[i] = i;
    std::sort(m_order.begin(), m_order.end(),
              [&](size_t a, size_t b) { return m_trial[a] > m_trial[b]; });
    double found = 0;
    for (size_t i : m_order) {
      if (m_trial[i] <= found) break;
      const Eigen::Vector3d p = c + r * m_dirs.row(static_cast<Eigen::Index>(i)).transpose();
      const double d = m_oracle.distance(p);
      if (d <= found) {
        m_trial[i] = d;  // |signed protrusion| <= d: cannot raise the maximum
        continue;
      }
      if (m_oracle.inside(p)) {
        m_trial[i] = -d;
        continue;
      }
      m_trial[i] = d;
      found = d;
      if (found >= cutoff) break;
    }
    return found;
  }

  const MeshOracle& m_oracle;
  MatX3d m_dirs;
  Eigen::Vector3d m_c = Eigen::Vector3d::Zero();
  double m_r = 0;
  std::vector<double> m_bound, m_trial;
  std::vector<size_t> m_order;
};

/// A rotation drawn uniformly from `seed` (Shoemake's quaternion method).
Eigen::Matrix3d random_rotation(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = u(rng), u3 = u(rng);
  const double two_pi = 2 * std::numbers::pi;
  const Eigen::Quaterniond q(
      std::sqrt(u1) * std::cos(two_pi * u3), std::sqrt(1 - u1) * std::sin(two_pi * u2),
      std::sqrt(1 - u1) * std::cos(two_pi * u2), std::sqrt(u1) * std::sin(two_pi * u3));
  return q.normalized().toRotationMatrix();
}

}  // namespace

CoverRadius::CoverRadius(const ReductionProblem& problem, const std::vector<int>& members,
                         double reach)
    : m_problem(problem), m_members(members), m_reach(reach) {
  if (members.empty()) throw ParameterError("CoverRadius: no members");
  if (!(reach >= 0))
    throw ParameterError("CoverRadius: reach must be >= 0, got " + std::to_string(reach));
}

double CoverRadius::operator()(const Eigen::Vector3d& c) {
  double moved = (c - m_c0).norm();
  if (m_shell.empty() || moved > m_reach) {
    rebuild(c);
    moved = 0;  // c is the new c0
  }
  const double slack = moved + 1e-9 * (m_r0 + moved);
  double r = 0;
  for (int b = 0; b < kBands; ++b) {
    if (m_band_begin[b] == m_band_begin[b + 1]) continue;
    if (m_band_max[b] + slack < r) break;  // this band and the next cannot reach r
    for (size_t k = m_band_begin[b]; k < m_band_begin[b + 1]; ++k) {
      const Eigen::Vector4d& s = m_shell[k];
      r = std::max(r, (s.head<3>() - c).norm() + s[3]);
    }
  }
  return r;
}

void CoverRadius::narrow(const Eigen::Vector3d& c, double reach) {
  if (reach > 0.5 * m_reach) return;
  m_reach = reach;
  rebuild(c);
}

void CoverRadius::rebuild(const Eigen::Vector3d& c0) {
  m_c0 = c0;
  m_reach0.resize(m_members.size());
  m_r0 = 0;
  for (size_t k = 0; k < m_members.size(); ++k) {
    m_reach0[k] = m_problem.reach(m_members[k], c0);
    m_r0 = std::max(m_r0, m_reach0[k]);
  }
  // Band b holds the reaches in (r0 - (b + 1) w, r0 - b w], w = 2 reach / kBands.
  const double width = 2 * m_reach / kBands;
  auto band_of = [&](double reach0) {
    return width > 0 ? std::min(kBands - 1, static_cast<int>((m_r0 - reach0) / width)) : 0;
  };
  std::array<size_t, kBands + 1> count{};
  m_band_max.fill(-std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < m_members.size(); ++k) {
    if (m_reach0[k] < m_r0 - 2 * m_reach) continue;
    const int b = band_of(m_reach0[k]);
    ++count[static_cast<size_t>(b) + 1];
    m_band_max[b] = std::max(m_band_max[b], m_reach0[k]);
  }
  for (int b = 0; b < kBands; ++b) count[b + 1] += count[b];
  m_band_begin = count;
  m_shell.resize(count[kBands]);
  for (size_t k = 0; k < m_members.size(); ++k) {
    if (m_reach0[k] < m_r0 - 2 * m_reach) continue;
    const int s = m_members[k];
    const Eigen::Vector3d p = m_problem.points.row(s).transpose();
    m_shell[count[static_cast<size_t>(band_of(m_reach0[k]))]++] =
        Eigen::Vector4d(p.x(), p.y(), p.z(), m_problem.gap[s]);
  }
}

MatX3d spiral_directions(int count) {
  if (count < 1)
    throw ParameterError("spiral_directions: count must be >= 1, got " + std::to_string(count));
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  MatX3d out(count, 3);
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * i;
    out.row(i) << rho * std::cos(phi), rho * std::sin(phi), z;
  }
  return out;
}

double sphere_protrusion(const MeshOracle& oracle, const Eigen::Vector3d& center, double radius,
                         const Eigen::Ref<const MatX3d>& directions) {
  std::vector<std::pair<double, Eigen::Index>> distance;
  distance.reserve(static_cast<size_t>(directions.rows()));
  for (Eigen::Index d = 0; d < directions.rows(); ++d) {
    distance.emplace_back(oracle.distance(center + radius * directions.row(d).transpose()), d);
  }
  // The largest distance among the outside points: the first outside one in
  // decreasing order of distance.
  std::sort(distance.begin(), distance.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [dist, d] : distance) {
    if (!(dist > 0)) break;
    if (!oracle.inside(center + radius * directions.row(d).transpose())) return dist;
  }
  return 0.0;
}

ProtrusionPolishResult polish_protrusion(const ReductionProblem& problem, const MeshOracle& oracle,
                                         FittedSphere& sphere, unsigned seed,
                                         const ProtrusionPolishOptions& options) {
  check_options(options);
  return polish_protrusion_on(
      problem, oracle, sphere,
      spiral_directions(options.search_directions) * random_rotation(seed).transpose(),
      spiral_directions(options.check_directions), options);
}

ProtrusionPolishResult polish_protrusion_on(const ReductionProblem& problem,
                                            const MeshOracle& oracle, FittedSphere& sphere,
                                            const Eigen::Ref<const MatX3d>& search_directions,
                                            const Eigen::Ref<const MatX3d>& check_directions,
                                            const ProtrusionPolishOptions& options) {
  check_options(options);
  if (search_directions.rows() < 1 || check_directions.rows() < 1)
    throw ParameterError("polish_protrusion_on: empty direction set");
  ProtrusionPolishResult result;
  if (sphere.members.empty()) return result;
  ProbeSet check(oracle, check_directions);
  ProbeSet search(oracle, search_directions);
  const double r0 = sphere.radius;
  if (options.max_evaluations == 0) return result;

  CoverRadius cover(problem, sphere.members, 2 * options.initial_step * r0);
  Eigen::Vector3d center = sphere.center;
  double radius = cover(center);
  double best = search.reset(center, radius);
  double step = options.initial_step * r0;
  // The 26 directions to the neighbours of a cube cell: axis-only steps stall
  // at the kinks of a largest-of-distances objective.
  std::vector<Eigen::Vector3d> pattern;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x != 0 || y != 0 || z != 0) pattern.push_back(Eigen::Vector3d(x, y, z).normalized());
  const int num_pattern = static_cast<int>(pattern.size());
  int last_direction = 0;
  while (step >= options.min_step * r0 && result.evaluations < options.max_evaluations &&
         best > 0) {
    bool improved = false;
    for (int k = 0; k < num_pattern && !improved && result.evaluations < options.max_evaluations;
         ++k) {
      const int direction = (last_direction + k) % num_pattern;  // the last successful one first
      const Eigen::Vector3d trial = center + step * pattern[static_cast<size_t>(direction)];
      const double r = cover(trial);
      ++result.evaluations;
      const double e = search.try_move(trial, r, best);
      if (e < best) {
        search.accept(trial, r);
        best = e, center = trial, radius = r, improved = true, last_direction = direction;
      }
    }
    if (!improved) {
      step *= 0.5;
      cover.narrow(center, 2 * step);
    }
  }
  if (center == sphere.center) return result;
  // The check points are evaluated only when the search moved the centre.
  result.checked = true;
  result.before = check.reset(sphere.center, sphere.radius);
  const double after = check.try_move(center, radius, result.before);
  result.after = result.before;
  if (!(after < result.before)) return result;
  assert(radius >= 0);
  sphere.center = center;
  sphere.radius = radius;
  sphere.depth = oracle.inside(center) ? oracle.distance(center) : 0.0;
  sphere.error = radius - sphere.depth;
  result.after = after;
  result.moved = true;
  return result;
}

}  // namespace icd::mesh
