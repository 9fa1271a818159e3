#include <icd/mesh/spheres/surface_sampling.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <icd/mesh/core/error.hpp>

namespace icd::mesh {
namespace {

constexpr double kInvSqrt3 = 0.57735026918962576451;
/// Column sampling (thin triangles): step between columns and between the
/// points of a column, relative to the spacing. Its sub-triangles are close
/// to right triangles with legs <= step, covering radius about 0.57 spacing,
/// like the lattice's spacing / sqrt(3).
constexpr double kColumnStep = 0.8;

void check_input(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F) {
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (!V.row(i).allFinite()) {
      throw InputError("sample_surface: vertex " + std::to_string(i) +
                       " has a non-finite coordinate");
    }
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (F(f, k) < 0 || F(f, k) >= V.rows()) {
        throw InputError("sample_surface: face " + std::to_string(f) +
                         " has out-of-range vertex index " + std::to_string(F(f, k)));
      }
    }
  }
}

}  // namespace

double surface_area(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F) {
  double total = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    total += 0.5 * (b - a).cross(c - a).norm();
  }
  return total;
}

double longest_bounding_box_side(const Eigen::Ref<const MatX3d>& V) {
  if (V.rows() == 0) return 0;
  return (V.colwise().maxCoeff() - V.colwise().minCoeff()).maxCoeff();
}

namespace {

/// Where a triangle's samples go, before they are written out.
struct SampleBuffers {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> gap, area;
  std::vector<int> face;
  int add(const Eigen::Vector3d& p, int f) {
    points.push_back(p);
    gap.push_back(0.0);
    area.push_back(0.0);
    face.push_back(f);
    return static_cast<int>(points.size()) - 1;
  }
};

/// The largest distance from a point of triangle (a, b, c) to its nearest
/// corner, from above: the circumradius when no angle is obtuse, else half
/// the longest edge (both at most longest / sqrt(3)). Degenerate triangles
/// (a segment) count as obtuse.
double covering_radius(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c) {
  const double ab = (b - a).squaredNorm(), bc = (c - b).squaredNorm(), ca = (a - c).squaredNorm();
  const double longest = std::max({ab, bc, ca});
  const double twice_area = (b - a).cross(c - a).norm();
  if (2 * longest >= ab + bc + ca || !(twice_area > 0)) return 0.5 * std::sqrt(longest);
  // R = |ab| |bc| |ca| / (4 area)
  return std::sqrt(ab * bc * ca) / (2 * twice_area);
}

/// Column sampling of a thin triangle (the lattice's n x n sub-triangles
/// would be needles, their number growing with the longest edge squared
/// whatever the area). The altitude onto the longest edge cuts it into two
/// right triangles; each is cut into columns perpendicular to its longer leg
/// (so the hypotenuse rises at most one step per step), at most `step`
/// apart, each holding points at most `step` apart from that leg to the
/// hypotenuse; neighbouring columns are joined into sub-triangles (a zipper
/// over their height fractions). The halves share the altitude's points
/// twice (as the lattice repeats edge points; harmless).
struct RightTriangle {
  Eigen::Vector3d o, a, b;  // right angle at o; columns perpendicular to o-a (the longer leg)
  int id_o, id_a, id_b;     // sample indices of the corners (-1: o is a new point)
};

/// The right triangles of triangle `corner` (global indices `ids`); empty
/// halves (the altitude's foot at a corner) are left out.
std::vector<RightTriangle> right_halves(const Eigen::Vector3d corner[3], const int ids[3]) {
  int p = 0;
  double longest = -1;
  for (int k = 0; k < 3; ++k) {
    const double len = (corner[(k + 1) % 3] - corner[k]).norm();
    if (len > longest) longest = len, p = k;
  }
  const int q = (p + 1) % 3, r = (p + 2) % 3;
  const Eigen::Vector3d pq = corner[q] - corner[p];
  const double t = longest > 0 ? std::clamp(pq.dot(corner[r] - corner[p]) / (longest * longest),
                                            0.0, 1.0)
                               : 0.0;
  const Eigen::Vector3d foot = corner[p] + t * pq;
  const int id_foot = t == 0 ? ids[p] : t == 1 ? ids[q] : -1;
  std::vector<RightTriangle> halves;
  for (int end : {p, q}) {
    if ((corner[end] - foot).norm() == 0 && id_foot != -1) continue;  // no such half
    const double leg = (corner[end] - foot).norm(), height = (corner[r] - foot).norm();
    if (leg >= height) {
      halves.push_back({foot, corner[end], corner[r], id_foot, ids[end], ids[r]});
    } else {
      halves.push_back({foot, corner[r], corner[end], id_foot, ids[r], ids[end]});
    }
  }
  return halves;
}

/// Columns of a right triangle: count along o-a, points per column.
int column_count(const RightTriangle& h, double step) {
  return std::max(1, static_cast<int>(std::ceil((h.a - h.o).norm() / step)));
}
int column_points(const RightTriangle& h, int n, int i, double step) {
  const double width = (1.0 - static_cast<double>(i) / n) * (h.b - h.o).norm();
  return static_cast<int>(std::ceil(width / step));  // intervals
}

/// Points the column sampling gives a triangle, corners included.
long long column_sample_count(const Eigen::Vector3d corner[3], double step) {
  const int ids[3] = {0, 1, 2};
  long long count = 0;
  for (const RightTriangle& h : right_halves(corner, ids)) {
    const int n = column_count(h, step);
    for (int i = 0; i <= n; ++i) count += column_points(h, n, i, step) + 1;
  }
  return count;
}

/// Samples triangle f (global corner indices `ids`) by columns `step`
/// apart, adding points, gaps and areas to `out`; returns the largest
/// covering radius of its sub-triangles.
double sample_columns(const Eigen::Vector3d corner[3], const int ids[3], int f, double step,
                      SampleBuffers& out) {
  double worst = 0;
  auto triangle = [&](int i0, int i1, int i2) {
    const Eigen::Vector3d a = out.points[static_cast<size_t>(i0)],
                          b = out.points[static_cast<size_t>(i1)],
                          c = out.points[static_cast<size_t>(i2)];
    const double radius = covering_radius(a, b, c);
    const double third = 0.5 * (b - a).cross(c - a).norm() / 3.0;
    worst = std::max(worst, radius);
    for (int id : {i0, i1, i2}) {
      const auto g = static_cast<size_t>(id);
      out.gap[g] = std::max(out.gap[g], radius);
      out.area[g] += third;
    }
  };
  std::vector<RightTriangle> halves = right_halves(corner, ids);
  int id_foot = -1;
  for (RightTriangle& h : halves) {
    if (h.id_o < 0) {
      if (id_foot < 0) id_foot = out.add(h.o, f);
      h.id_o = id_foot;
    }
  }
  for (const RightTriangle& h : halves) {
    const int n = column_count(h, step);
    std::vector<std::vector<int>> columns;
    for (int i = 0; i <= n; ++i) {
      const double s = static_cast<double>(i) / n;
      const Eigen::Vector3d bottom = h.o + s * (h.a - h.o), top = h.b + s * (h.a - h.b);
      const int k = i == n ? 0 : column_points(h, n, i, step);
      std::vector<int> column;
      for (int j = 0; j <= k; ++j) {
        int id;
        if (i == n) {
          id = h.id_a;
        } else if (i == 0 && j == 0) {
          id = h.id_o;
        } else if (i == 0 && j == k) {
          id = h.id_b;
        } else {
          id = out.add(bottom + (static_cast<double>(j) / k) * (top - bottom), f);
        }
        column.push_back(id);
      }
      columns.push_back(std::move(column));
    }
    for (size_t c = 0; c + 1 < columns.size(); ++c) {
      const std::vector<int>& a = columns[c];
      const std::vector<int>& b = columns[c + 1];
      const auto ka = static_cast<long long>(a.size()) - 1,
                 kb = static_cast<long long>(b.size()) - 1;
      if (ka == 0 && kb == 0) {
        triangle(a[0], b[0], b[0]);  // a segment of a degenerate triangle
        continue;
      }
      long long i = 0, j = 0;
      while (i < ka || j < kb) {
        // Advance on the column whose next point sits lower (height fractions).
        if (j == kb || (i < ka && (i + 1) * kb <= (j + 1) * ka)) {
          triangle(a[static_cast<size_t>(i)], a[static_cast<size_t>(i + 1)],
                   b[static_cast<size_t>(j)]);
          ++i;
        } else {
          triangle(a[static_cast<size_t>(i)], b[static_cast<size_t>(j + 1)],
                   b[static_cast<size_t>(j)]);
          ++j;
        }
      }
    }
  }
  return worst;
}

}  // namespace

SurfaceSamples sample_surface(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F,
                              const SamplingOptions& options) {
  if (!(options.spacing > 0) || !std::isfinite(options.spacing)) {
    throw ParameterError("SamplingOptions::spacing must be positive and finite, got " +
                         std::to_string(options.spacing));
  }
  if (!(options.column_ratio >= 1)) {
    throw ParameterError("SamplingOptions::column_ratio must be >= 1, got " +
                         std::to_string(options.column_ratio));
  }
  check_input(V, F);
  const auto nv = static_cast<size_t>(V.rows());
  SampleBuffers buffers;
  std::vector<Eigen::Vector3d>& points = buffers.points;
  std::vector<double>& gap = buffers.gap;
  std::vector<double>& area = buffers.area;
  std::vector<int>& face = buffers.face;
  points.resize(nv);
  gap.assign(nv, 0.0);
  area.assign(nv, 0.0);
  face.assign(nv, -1);
  for (size_t i = 0; i < nv; ++i) points[i] = V.row(static_cast<Eigen::Index>(i));
  const double column_step = kColumnStep * options.spacing;

  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const int ia = F(f, 0), ib = F(f, 1), ic = F(f, 2);
    const Eigen::Vector3d a = V.row(ia), b = V.row(ib), c = V.row(ic);
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const double tri_area = 0.5 * (b - a).cross(c - a).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(longest / options.spacing)));
    if (n >= 2) {
      const Eigen::Vector3d corner[3] = {a, b, c};
      const long long lattice = static_cast<long long>(n + 1) * (n + 2) / 2;
      if (static_cast<double>(lattice) >=
          options.column_ratio * static_cast<double>(column_sample_count(corner, column_step))) {
        const int ids[3] = {ia, ib, ic};
        // The gap stays within spacing / sqrt(3), as on the lattice: a
        // finer step where a zipper triangle came out too wide (rare).
        const size_t mark = points.size();
        std::vector<double> saved_gap{gap[static_cast<size_t>(ia)], gap[static_cast<size_t>(ib)],
                                      gap[static_cast<size_t>(ic)]};
        std::vector<double> saved_area{area[static_cast<size_t>(ia)],
                                       area[static_cast<size_t>(ib)],
                                       area[static_cast<size_t>(ic)]};
        bool done = false;
        double step = column_step;
        for (int attempt = 0; attempt < 8 && !done; ++attempt, step *= 0.8) {
          const double worst = sample_columns(corner, ids, static_cast<int>(f), step, buffers);
          done = worst <= options.spacing * kInvSqrt3;
          if (done) break;
          points.resize(mark), gap.resize(mark), area.resize(mark), face.resize(mark);
          for (int k = 0; k < 3; ++k) {
            gap[static_cast<size_t>(ids[k])] = saved_gap[static_cast<size_t>(k)];
            area[static_cast<size_t>(ids[k])] = saved_area[static_cast<size_t>(k)];
          }
        }
        if (done) {
          for (int id : ids)
            if (face[static_cast<size_t>(id)] < 0)
              face[static_cast<size_t>(id)] = static_cast<int>(f);
          continue;
        }
        // else: the lattice below (never seen; kept as the guaranteed way out)
      }
    }
    const double sub_gap = longest / n * kInvSqrt3;
    const double sub_area = tri_area / (static_cast<double>(n) * n);
    // Lattice point (i, j): a + i/n (b - a) + j/n (c - a), i + j <= n. Each
    // sub-triangle gives a third of its area to each of its corners.
    auto lattice_index = [n](int i, int j) { return j * (n + 1) - j * (j - 1) / 2 + i; };
    const int count = (n + 1) * (n + 2) / 2;
    std::vector<int> global(static_cast<size_t>(count), -1);
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i + j <= n; ++i) {
        int g;
        if (i == 0 && j == 0) {
          g = ia;
        } else if (i == n && j == 0) {
          g = ib;
        } else if (i == 0 && j == n) {
          g = ic;
        } else {
          g = static_cast<int>(points.size());
          points.push_back(a + (b - a) * (static_cast<double>(i) / n) +
                           (c - a) * (static_cast<double>(j) / n));
          gap.push_back(0.0);
          area.push_back(0.0);
          face.push_back(static_cast<int>(f));
        }
        global[static_cast<size_t>(lattice_index(i, j))] = g;
      }
    }
    auto corner = [&](int i, int j) {
      const auto g = static_cast<size_t>(global[static_cast<size_t>(lattice_index(i, j))]);
      gap[g] = std::max(gap[g], sub_gap);
      area[g] += sub_area / 3.0;
      if (face[g] < 0) face[g] = static_cast<int>(f);
    };
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i + j < n; ++i) {
        corner(i, j), corner(i + 1, j), corner(i, j + 1);  // upward sub-triangle
        if (i + j + 1 < n) corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1);  // downward
      }
    }
  }

  SurfaceSamples out;
  const auto ns = static_cast<Eigen::Index>(points.size());
  out.points.resize(ns, 3);
  out.gap.resize(ns);
  out.area.resize(ns);
  out.face.resize(ns);
  for (Eigen::Index s = 0; s < ns; ++s) {
    out.points.row(s) = points[static_cast<size_t>(s)];
    out.gap[s] = gap[static_cast<size_t>(s)];
    out.area[s] = area[static_cast<size_t>(s)];
    out.face[s] = face[static_cast<size_t>(s)];
  }
  out.num_vertex_samples = static_cast<int>(nv);
  return out;
}

}  // namespace icd::mesh
