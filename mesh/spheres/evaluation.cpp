#include <icd/mesh/spheres/evaluation.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <unordered_map>

#include <Eigen/Geometry>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

namespace icd::mesh {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Seed of a sphere's random draws from its geometry (the bits of x, y, z, r
// mixed with splitmix64's finalizer), so that the estimates do not depend on
// the order of the spheres in the tree.
unsigned geometry_seed(const collision::Sphere& s, uint64_t salt) {
  uint64_t h = salt;
  for (double v : {s.x, s.y, s.z, s.r}) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    h ^= bits + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
    h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
    h ^= h >> 31;
  }
  return static_cast<unsigned>(h ^ (h >> 32));
}

/// Spheres of one level bucketed in a uniform grid; very large spheres are
/// kept in a separate list tested for every query.
class SphereGrid {
 public:
  SphereGrid(std::vector<collision::Sphere> spheres) : m_spheres(std::move(spheres)) {
    std::vector<double> radii;
    for (const auto& s : m_spheres) radii.push_back(s.r);
    std::nth_element(radii.begin(), radii.begin() + static_cast<long>(radii.size() / 2),
                     radii.end());
    m_cell = std::max(radii[radii.size() / 2], 1e-9);
    for (int i = 0; i < static_cast<int>(m_spheres.size()); ++i) {
      const auto& s = m_spheres[static_cast<size_t>(i)];
      if (s.r > 4 * m_cell) {
        m_big.push_back(i);
        continue;
      }
      const Eigen::Vector3i lo = cell({s.x - s.r, s.y - s.r, s.z - s.r});
      const Eigen::Vector3i hi = cell({s.x + s.r, s.y + s.r, s.z + s.r});
      for (int a = lo.x(); a <= hi.x(); ++a)
        for (int b = lo.y(); b <= hi.y(); ++b)
          for (int c = lo.z(); c <= hi.z(); ++c) m_cells[key({a, b, c})].push_back(i);
    }
    // Cells whose keys collide share a bucket: list each sphere once, so that
    // the counts below count spheres, not cells.
    for (auto& [cell_key, list] : m_cells) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
    }
  }

  /// Calls visit(i) for each sphere i that contains p, until it returns true.
  template <class Visit>
  void for_each_containing(const Eigen::Vector3d& p, Visit&& visit) const {
    for (int i : m_big) {
      if (inside(i, p) && visit(i)) return;
    }
    auto it = m_cells.find(key(cell(p)));
    if (it == m_cells.end()) return;
    for (int i : it->second) {
      if (inside(i, p) && visit(i)) return;
    }
  }

  /// Number of spheres that contain p, counted up to `limit`; `found` (if
  /// not null) is set to the last one found (with a count of 1, the only one).
  int count_containing(const Eigen::Vector3d& p, int limit, int* found = nullptr) const {
    int count = 0;
    for_each_containing(p, [&](int i) {
      if (found != nullptr) *found = i;
      return ++count >= limit;
    });
    return count;
  }

  /// How far along the unit direction n the spheres containing p reach from
  /// p (0 when none does).
  double reach_along(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
    double reach = 0;
    for_each_containing(p, [&](int i) {
      const auto& s = m_spheres[static_cast<size_t>(i)];
      const Eigen::Vector3d d = s.center() - p;
      const double along = d.dot(n);
      reach = std::max(
          reach, along + std::sqrt(std::max(0.0, s.r * s.r - d.squaredNorm() + along * along)));
      return false;
    });
    return reach;
  }

  /// Distance from p to the nearest sphere (<= 0 when covered); brute force.
  double gap(const Eigen::Vector3d& p) const {
    double best = kInf;
    for (const auto& s : m_spheres) best = std::min(best, (p - s.center()).norm() - s.r);
    return best;
  }

 private:
  bool inside(int i, const Eigen::Vector3d& p) const {
    const auto& s = m_spheres[static_cast<size_t>(i)];
    return (p - s.center()).squaredNorm() <= s.r * s.r;
  }
  Eigen::Vector3i cell(const Eigen::Vector3d& p) const {
    return {static_cast<int>(std::floor(p.x() / m_cell)),
            static_cast<int>(std::floor(p.y() / m_cell)),
            static_cast<int>(std::floor(p.z() / m_cell))};
  }
  static long long key(const Eigen::Vector3i& c) {
    return (static_cast<long long>(c.x()) * 73856093LL) ^
           (static_cast<long long>(c.y()) * 19349663LL) ^
           (static_cast<long long>(c.z()) * 83492791LL);
  }

  std::vector<collision::Sphere> m_spheres;
  double m_cell = 1;
  std::vector<int> m_big;
  std::unordered_map<long long, std::vector<int>> m_cells;
};

void check_tree(const collision::SphereTree& tree) {
  const int n = tree.num_nodes();
  if (n == 0 || tree.num_levels() < 1 || tree.level_offset.back() != n ||
      static_cast<int>(tree.first_child.size()) != n ||
      static_cast<int>(tree.child_count.size()) != n) {
    throw ParameterError("evaluate_sphere_tree: the tree is empty or its arrays are inconsistent");
  }
  for (const auto& s : tree.spheres) {
    if (!std::isfinite(s.x) || !std::isfinite(s.y) || !std::isfinite(s.z) || !(s.r >= 0)) {
      throw ParameterError(
          "evaluate_sphere_tree: a sphere has a non-finite centre or a negative radius");
    }
  }
}

}  // namespace

MatX3d probe_directions(int subdivisions) { return make_icosphere(subdivisions, 1.0).V; }

Eigen::Matrix3d toolkit_probe_frame() {
  Eigen::Matrix3d frame;
  frame << 0, 0, 1, 0, 1, 0, 1, 0, 0;
  return frame;
}

double visit_coverage_samples(const SurfaceMesh& mesh, double spacing,
                              const CoverageSampleVisitor& visit) {
  if (!(spacing > 0)) throw ParameterError("visit_coverage_samples: spacing must be > 0");
  double total_area = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                          c = mesh.V.row(mesh.F(f, 2));
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const Eigen::Vector3d normal = cross.normalized();
    const int n = std::max(1, static_cast<int>(std::ceil(longest / spacing)));
    const double sub_area = 0.5 * cross.norm() / (static_cast<double>(n) * n);
    total_area += sub_area * n * n;
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i + j <= n; ++i) {
        // Number of sub-triangles having lattice point (i, j) as a corner.
        const bool corner = (i == 0 && j == 0) || (i == n && j == 0) || (i == 0 && j == n);
        const bool edge = (i == 0 || j == 0 || i + j == n);
        const int incident = corner ? 1 : (edge ? 3 : 6);
        const double weight = sub_area * incident / 3.0;
        const Eigen::Vector3d p =
            a + (b - a) * (static_cast<double>(i) / n) + (c - a) * (static_cast<double>(j) / n);
        visit(p, normal, weight);
      }
    }
  }
  return total_area;
}

std::vector<LevelMetrics> evaluate_sphere_tree(const SurfaceMesh& mesh,
                                               const collision::SphereTree& tree,
                                               const EvaluationOptions& options) {
  if (!(options.normalized_size > 0) || !(options.coverage_spacing > 0) ||
      options.shell_samples < 0 || options.probe_rotations < 0) {
    throw ParameterError(
        "EvaluationOptions: normalized_size and coverage_spacing must be positive, "
        "shell_samples and probe_rotations >= 0");
  }
  const Eigen::Matrix3d& frame = options.probe_frame;
  if (!frame.allFinite() ||
      !(frame.transpose() * frame).isApprox(Eigen::Matrix3d::Identity(), 1e-9)) {
    throw ParameterError("EvaluationOptions: probe_frame must be an orthogonal matrix");
  }
  check_tree(tree);
  const double side = longest_bounding_box_side(mesh.V);
  if (!(side > 0)) throw InputError("evaluate_sphere_tree: the mesh is empty or degenerate");
  const double scale = options.normalized_size / side;
  SurfaceMesh scaled = mesh;
  scaled.V *= scale;
  std::vector<collision::Sphere> spheres = tree.spheres;
  for (auto& s : spheres) s.x *= scale, s.y *= scale, s.z *= scale, s.r *= scale;

  const MeshOracle oracle(close_holes(scaled));
  const MatX3d probes42 = probe_directions(1) * frame.transpose(),
               probes162 = probe_directions(2) * frame.transpose();
  auto sphere_error = [&](const collision::Sphere& s, const MatX3d& dirs) {
    double err = 0;
    for (Eigen::Index d = 0; d < dirs.rows(); ++d) {
      const Eigen::Vector3d p = s.center() + s.r * dirs.row(d).transpose();
      if (!oracle.inside(p)) err = std::max(err, oracle.distance(p));
    }
    return err;
  };
  // Random orientations of the 42 probes, per sphere and fixed by its geometry.
  const MatX3d unturned42 = probe_directions(1);
  auto rotated_error = [&](const collision::Sphere& s) {
    if (options.probe_rotations == 0) return 0.0;
    std::mt19937 rng(geometry_seed(s, 977u));
    std::normal_distribution<double> normal(0.0, 1.0);
    double sum = 0;
    for (int k = 0; k < options.probe_rotations; ++k) {
      // A normalized Gaussian quaternion is a uniformly random rotation.
      const Eigen::Quaterniond q =
          Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
      sum += sphere_error(s, unturned42 * q.toRotationMatrix().transpose());
    }
    return sum / options.probe_rotations;
  };

  const int num_levels = tree.num_levels();
  std::vector<LevelMetrics> out(static_cast<size_t>(num_levels));
  std::vector<int32_t> parent(static_cast<size_t>(tree.num_nodes()), -1);
  for (int i = 0; i < tree.num_nodes(); ++i) {
    for (int k = 0; k < tree.child_count[static_cast<size_t>(i)]; ++k) {
      parent[static_cast<size_t>(tree.first_child[static_cast<size_t>(i)] + k)] = i;
    }
  }
  std::vector<SphereGrid> grids;
  // Per level: which spheres cover some vertex or dense sample alone.
  std::vector<std::vector<char>> alone(static_cast<size_t>(num_levels));
  std::vector<std::vector<double>> errors42(static_cast<size_t>(num_levels)),
      errors162(static_cast<size_t>(num_levels));
  auto note_coverage = [&](int l, const Eigen::Vector3d& p) {
    int only = -1;
    const int count = grids[static_cast<size_t>(l)].count_containing(p, 2, &only);
    if (count == 1) alone[static_cast<size_t>(l)][static_cast<size_t>(only)] = 1;
    return count > 0;
  };
  for (int l = 0; l < num_levels; ++l) {
    LevelMetrics& m = out[static_cast<size_t>(l)];
    m.level = l;
    const int begin = tree.level_offset[static_cast<size_t>(l)],
              end = tree.level_offset[static_cast<size_t>(l) + 1];
    m.num_spheres = end - begin;
    for (int i = begin; i < end; ++i) {
      const auto& s = spheres[static_cast<size_t>(i)];
      const double e42 = sphere_error(s, probes42), e162 = sphere_error(s, probes162);
      const double e42r = rotated_error(s);
      m.worst_error_42_rotated = std::max(m.worst_error_42_rotated, e42r);
      m.mean_error_42_rotated += e42r / m.num_spheres;
      m.worst_error_42 = std::max(m.worst_error_42, e42);
      m.worst_error_162 = std::max(m.worst_error_162, e162);
      m.mean_error_42 += e42 / m.num_spheres;
      m.mean_error_162 += e162 / m.num_spheres;
      errors42[static_cast<size_t>(l)].push_back(e42);
      errors162[static_cast<size_t>(l)].push_back(e162);
      const int p = parent[static_cast<size_t>(i)];
      if (p >= 0) {
        const auto& ps = spheres[static_cast<size_t>(p)];
        m.max_child_protrusion =
            std::max(m.max_child_protrusion, (s.center() - ps.center()).norm() + s.r - ps.r);
      }
    }
    grids.emplace_back(
        std::vector<collision::Sphere>(spheres.begin() + begin, spheres.begin() + end));
    alone[static_cast<size_t>(l)].assign(static_cast<size_t>(m.num_spheres), 0);
    for (Eigen::Index v = 0; v < scaled.V.rows(); ++v) {
      if (!note_coverage(l, scaled.V.row(v).transpose())) ++m.num_uncovered_vertices;
    }
  }

  // Dense coverage, streamed triangle by triangle (no sample storage), and
  // the area-weighted histogram of each level's reach along the normal.
  std::vector<double> uncovered_area(static_cast<size_t>(num_levels), 0.0);
  constexpr double kThicknessBin = 0.5;  // normalized units
  constexpr int kThicknessBins = 16000;  // the last bin takes everything beyond
  std::vector<std::vector<double>> thickness(static_cast<size_t>(num_levels),
                                             std::vector<double>(kThicknessBins, 0.0));
  const double total_area = visit_coverage_samples(
      scaled, options.coverage_spacing,
      [&](const Eigen::Vector3d& p, const Eigen::Vector3d& normal, double weight) {
        for (int l = 0; l < num_levels; ++l) {
          LevelMetrics& m = out[static_cast<size_t>(l)];
          ++m.num_dense_samples;
          const bool covered = note_coverage(l, p);
          const double reach = covered ? grids[static_cast<size_t>(l)].reach_along(p, normal) : 0.0;
          const int bin =
              std::min(kThicknessBins - 1, static_cast<int>(std::floor(reach / kThicknessBin)));
          thickness[static_cast<size_t>(l)][static_cast<size_t>(bin)] += weight;
          if (covered) continue;
          ++m.num_uncovered_samples;
          uncovered_area[static_cast<size_t>(l)] += weight;
          m.max_uncovered_gap = std::max(m.max_uncovered_gap, grids[static_cast<size_t>(l)].gap(p));
        }
      });
  // Shell volume: each sphere's part beyond the depth of its centre (the
  // rest is inside the object), sampled uniformly by volume; a sample outside
  // the object counts 1 / (spheres containing it), so the sum is the volume
  // of the union outside the object.
  for (int l = 0; l < num_levels && options.shell_samples > 0 && total_area > 0; ++l) {
    LevelMetrics& m = out[static_cast<size_t>(l)];
    const int begin = tree.level_offset[static_cast<size_t>(l)];
    double volume = 0;
    for (int i = 0; i < m.num_spheres; ++i) {
      const auto& s = spheres[static_cast<size_t>(begin + i)];
      const double depth = oracle.inside(s.center()) ? oracle.distance(s.center()) : 0.0;
      if (depth >= s.r) continue;
      const double r3 = s.r * s.r * s.r, d3 = depth * depth * depth;
      const double part = 4.0 / 3.0 * M_PI * (r3 - d3) / options.shell_samples;
      std::mt19937 rng(geometry_seed(s, 12345u));
      std::uniform_real_distribution<double> uniform(0.0, 1.0);
      std::normal_distribution<double> normal(0.0, 1.0);
      for (int k = 0; k < options.shell_samples; ++k) {
        Eigen::Vector3d dir(normal(rng), normal(rng), normal(rng));
        dir.normalize();
        const double rho = std::cbrt(d3 + uniform(rng) * (r3 - d3));
        const Eigen::Vector3d p = s.center() + rho * dir;
        if (oracle.inside(p)) continue;
        const int count =
            grids[static_cast<size_t>(l)].count_containing(p, std::numeric_limits<int>::max());
        volume += part / std::max(count, 1);
      }
    }
    m.shell_thickness = volume / total_area;
  }
  for (int l = 0; l < num_levels; ++l) {
    LevelMetrics& m = out[static_cast<size_t>(l)];
    m.uncovered_area_fraction =
        total_area > 0 ? uncovered_area[static_cast<size_t>(l)] / total_area : 0.0;
    // Area-weighted quantiles of the reach (bin centres).
    const auto& hist = thickness[static_cast<size_t>(l)];
    auto quantile = [&](double q) {
      double cumulative = 0;
      for (int bin = 0; bin < kThicknessBins; ++bin) {
        cumulative += hist[static_cast<size_t>(bin)];
        if (cumulative >= q * total_area) return (bin + 0.5) * kThicknessBin;
      }
      return (kThicknessBins - 0.5) * kThicknessBin;
    };
    if (total_area > 0) {
      m.thickness_median = quantile(0.5);
      m.thickness_p90 = quantile(0.9);
    }
    int covering = 0;
    for (int i = 0; i < m.num_spheres; ++i) {
      if (!alone[static_cast<size_t>(l)][static_cast<size_t>(i)]) continue;
      ++covering;
      m.mean_error_42_covering += errors42[static_cast<size_t>(l)][static_cast<size_t>(i)];
      m.mean_error_162_covering += errors162[static_cast<size_t>(l)][static_cast<size_t>(i)];
    }
    m.num_redundant_spheres = m.num_spheres - covering;
    if (covering > 0) {
      m.mean_error_42_covering /= covering;
      m.mean_error_162_covering /= covering;
    }
  }
  return out;
}

}  // namespace icd::mesh
