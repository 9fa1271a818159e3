#include <icd/mesh/spheres/medial_axis.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/parallel.hpp>

namespace icd::mesh {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
/// Per-cell cache of the inside test, so that a refinement round only tests
/// the cells its insertions created (CGAL keeps the info of untouched cells).
struct CellInfo {
  signed char state = 0;  // 0: not tested yet, 1: outside or flat, 2: inside
  double center[3] = {0, 0, 0};
  double circumradius = 0;
  double inscribed = 0;
};
using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, Kernel>;
using Cb =
    CGAL::Triangulation_cell_base_with_info_3<CellInfo, Kernel,
                                              CGAL::Delaunay_triangulation_cell_base_3<Kernel>>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, Tds>;

Eigen::Vector3d to_eigen(const Point& p) { return {p.x(), p.y(), p.z()}; }

/// Circumcentre of a tetrahedron, or false when it is (nearly) flat: solves
/// 2 (p_i - p_0) . x = |p_i - p_0|^2 for x = centre - p_0.
bool circumcenter(const Eigen::Vector3d p[4], Eigen::Vector3d& center) {
  Eigen::Matrix3d A;
  Eigen::Vector3d b;
  double scale = 0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d d = p[i + 1] - p[0];
    A.row(i) = 2.0 * d.transpose();
    b[i] = d.squaredNorm();
    scale = std::max(scale, d.norm());
  }
  const double det = A.determinant();
  if (!(std::abs(det) > 1e-10 * 8.0 * scale * scale * scale)) return false;
  center = p[0] + A.inverse() * b;
  return center.allFinite();
}

/// One inner Voronoi vertex: circumcentre, circumradius, and the samples
/// (vertex infos) of its Delaunay cell.
struct InnerVertex {
  Eigen::Vector3d center;
  double circumradius;
  double inscribed;
  int corner[4];
};

/// Classifies the cells not tested yet (circumcentre inside the mesh?), one
/// block of cells per task on the workers' oracles; each task writes only
/// its own cells' infos.
void classify_new_cells(Delaunay& dt, const std::vector<const MeshOracle*>& oracles) {
  std::vector<Delaunay::Cell_handle> fresh;
  for (auto cell = dt.finite_cells_begin(); cell != dt.finite_cells_end(); ++cell) {
    if (cell->info().state == 0) fresh.push_back(cell);
  }
  constexpr size_t kBlock = 512;
  parallel_for((fresh.size() + kBlock - 1) / kBlock, static_cast<int>(oracles.size()),
               [&](size_t block, int worker) {
                 const MeshOracle& oracle = *oracles[static_cast<size_t>(worker)];
                 const size_t end = std::min(fresh.size(), (block + 1) * kBlock);
                 for (size_t i = block * kBlock; i < end; ++i) {
                   CellInfo& info = fresh[i]->info();
                   Eigen::Vector3d corners[4];
                   for (int k = 0; k < 4; ++k) corners[k] = to_eigen(fresh[i]->vertex(k)->point());
                   Eigen::Vector3d center;
                   info.state = 1;
                   if (circumcenter(corners, center) && oracle.inside(center)) {
                     info.state = 2;
                     for (int k = 0; k < 3; ++k) info.center[k] = center[k];
                     info.circumradius = (center - corners[0]).norm();
                     info.inscribed = oracle.distance(center);
                   }
                 }
               });
}

std::vector<InnerVertex> inner_vertices(Delaunay& dt,
                                        const std::vector<const MeshOracle*>& oracles) {
  classify_new_cells(dt, oracles);
  std::vector<InnerVertex> out;
  for (auto cell = dt.finite_cells_begin(); cell != dt.finite_cells_end(); ++cell) {
    const CellInfo& info = cell->info();
    if (info.state != 2) continue;
    InnerVertex v;
    v.center = Eigen::Vector3d(info.center[0], info.center[1], info.center[2]);
    v.circumradius = info.circumradius;
    v.inscribed = info.inscribed;
    for (int k = 0; k < 4; ++k) v.corner[k] = cell->vertex(k)->info();
    out.push_back(v);
  }
  return out;
}

}  // namespace

MedialSpheres approximate_medial_axis(const MeshOracle& oracle, const SurfaceSamples& samples,
                                      const MedialAxisOptions& options) {
  return approximate_medial_axis(std::vector<const MeshOracle*>{&oracle}, samples, options);
}

MedialSpheres approximate_medial_axis(const std::vector<const MeshOracle*>& oracles,
                                      const SurfaceSamples& samples,
                                      const MedialAxisOptions& options) {
  if (oracles.empty() || std::find(oracles.begin(), oracles.end(), nullptr) != oracles.end())
    throw ParameterError("approximate_medial_axis: needs at least one oracle, and no null one");
  const MeshOracle& oracle = *oracles.front();
  if (options.refinement_iterations < 0 || options.max_insertions_per_iteration < 0) {
    throw ParameterError(
        "MedialAxisOptions: refinement_iterations and max_insertions_per_iteration must be >= 0");
  }
  if (!(options.error_tolerance > 0)) {
    throw ParameterError("MedialAxisOptions::error_tolerance must be positive, got " +
                         std::to_string(options.error_tolerance));
  }
  const auto ns = static_cast<int>(samples.points.rows());
  if (ns < 4)
    throw InputError("approximate_medial_axis: need at least 4 samples, got " + std::to_string(ns));

  std::vector<std::pair<Point, int>> input;
  input.reserve(static_cast<size_t>(ns));
  for (int s = 0; s < ns; ++s) {
    input.emplace_back(Point(samples.points(s, 0), samples.points(s, 1), samples.points(s, 2)), s);
  }
  Delaunay dt(input.begin(), input.end());
  if (dt.dimension() < 3) throw InputError("approximate_medial_axis: the samples are coplanar");

  MedialSpheres out;
  std::vector<InnerVertex> inner = inner_vertices(dt, oracles);
  int next_info = ns;  // inserted points get infos >= ns (not samples)
  for (int it = 0; it < options.refinement_iterations; ++it) {
    // Worst spheres first, so that the insertion budget goes where the error is.
    std::vector<std::pair<double, int>> bad;
    for (int i = 0; i < static_cast<int>(inner.size()); ++i) {
      const double err =
          inner[static_cast<size_t>(i)].circumradius - inner[static_cast<size_t>(i)].inscribed;
      if (err > options.error_tolerance) bad.emplace_back(-err, i);
    }
    if (bad.empty()) break;
    std::sort(bad.begin(), bad.end());
    if (static_cast<int>(bad.size()) > options.max_insertions_per_iteration) {
      bad.resize(static_cast<size_t>(options.max_insertions_per_iteration));
    }
    // The surface points nearest the bad centres do not depend on the
    // insertions: found in parallel, inserted in order.
    std::vector<Eigen::Vector3d> nearest(bad.size());
    parallel_for(bad.size(), static_cast<int>(oracles.size()), [&](size_t k, int worker) {
      nearest[k] = oracles[static_cast<size_t>(worker)]->closest_point(
          inner[static_cast<size_t>(bad[k].second)].center);
    });
    int inserted = 0;
    for (const Eigen::Vector3d& q : nearest) {
      const Point p(q.x(), q.y(), q.z());
      Delaunay::Locate_type lt;
      int li, lj;
      const auto cell = dt.locate(p, lt, li, lj);
      if (lt == Delaunay::VERTEX) continue;
      auto vh = dt.insert(p, cell);
      vh->info() = next_info++;
      ++inserted;
    }
    out.num_inserted += inserted;
    if (inserted == 0) break;
    inner = inner_vertices(dt, oracles);
  }

  // Cover spheres for samples that no inner cell touches (thin features).
  std::vector<char> touched(static_cast<size_t>(ns), 0);
  for (const auto& v : inner) {
    for (int k = 0; k < 4; ++k) {
      if (v.corner[k] < ns) touched[static_cast<size_t>(v.corner[k])] = 1;
    }
  }
  const SurfaceMesh& mesh = oracle.mesh();
  std::vector<Eigen::Vector3d> cover_centers;
  std::vector<double> cover_radii;
  for (int s = 0; s < ns; ++s) {
    if (touched[static_cast<size_t>(s)]) continue;
    const int f = samples.face[s];
    Eigen::Vector3d center = samples.points.row(s);
    if (f >= 0 && f < mesh.F.rows()) {
      const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                            c = mesh.V.row(mesh.F(f, 2));
      const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
      const double step = 0.25 * samples.gap[s];
      if (n.allFinite() && step > 0 && oracle.inside(center - step * n)) center -= step * n;
    }
    cover_centers.push_back(center);
    cover_radii.push_back(oracle.distance(center));
  }

  const auto nm = static_cast<Eigen::Index>(inner.size() + cover_centers.size());
  out.centers.resize(nm, 3);
  out.radii.resize(nm);
  out.circumradii.resize(nm);
  Eigen::Index m = 0;
  for (const auto& v : inner) {
    out.centers.row(m) = v.center;
    out.radii[m] = v.inscribed;
    out.circumradii[m] = v.circumradius;
    ++m;
  }
  out.num_voronoi = static_cast<int>(inner.size());
  for (size_t i = 0; i < cover_centers.size(); ++i) {
    out.centers.row(m) = cover_centers[i];
    out.radii[m] = cover_radii[i];
    out.circumradii[m] = cover_radii[i];
    ++m;
  }
  return out;
}

}  // namespace icd::mesh
