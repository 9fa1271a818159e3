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

SurfaceSamples sample_surface(const Eigen::Ref<const MatX3d>& V, const Eigen::Ref<const MatX3i>& F,
                              const SamplingOptions& options) {
  if (!(options.spacing > 0) || !std::isfinite(options.spacing)) {
    throw ParameterError("SamplingOptions::spacing must be positive and finite, got " +
                         std::to_string(options.spacing));
  }
  check_input(V, F);
  const auto nv = static_cast<size_t>(V.rows());
  std::vector<Eigen::Vector3d> points(nv);
  std::vector<double> gap(nv, 0.0), area(nv, 0.0);
  std::vector<int> face(nv, -1);
  for (size_t i = 0; i < nv; ++i) points[i] = V.row(static_cast<Eigen::Index>(i));

  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const int ia = F(f, 0), ib = F(f, 1), ic = F(f, 2);
    const Eigen::Vector3d a = V.row(ia), b = V.row(ib), c = V.row(ic);
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const double tri_area = 0.5 * (b - a).cross(c - a).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(longest / options.spacing)));
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
