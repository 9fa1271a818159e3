#include <icd/mesh/pipeline/tetrahedralize.hpp>

#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polyhedral_mesh_domain_3.h>
#include <CGAL/Random.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/refine_mesh_3.h>

#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/pipeline/cgal_convert.hpp>

namespace icd::mesh {
namespace {

using detail::CgalMesh;
using detail::Kernel;
using Domain = CGAL::Polyhedral_mesh_domain_3<CgalMesh, Kernel>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

/// Seeds the triangulation with surface points: one input vertex per voxel of
/// edge `spacing` (the first in index order), plus the domain's own initial
/// points. CGAL's default seeding (rays from the bounding-box centre) can miss
/// thin or non-convex parts (a torus at coarse sizes yields no cell at all).
void seed(C3t3& c3t3, const Domain& domain, const SurfaceMesh& surface, double spacing) {
  std::vector<std::pair<Domain::Point_3, Domain::Index>> pts;
  domain.construct_initial_points_object()(std::back_inserter(pts), 8);
  if (pts.empty()) return;
  const Domain::Index surface_index = pts.front().second;
  const Eigen::RowVector3d lo = surface.V.colwise().minCoeff();
  std::set<std::array<long long, 3>> taken;
  for (Eigen::Index i = 0; i < surface.V.rows(); ++i) {
    const Eigen::RowVector3d c = ((surface.V.row(i) - lo) / spacing).array().floor();
    if (taken
            .insert({static_cast<long long>(c[0]), static_cast<long long>(c[1]),
                     static_cast<long long>(c[2])})
            .second)
      pts.emplace_back(Domain::Point_3(surface.V(i, 0), surface.V(i, 1), surface.V(i, 2)),
                       surface_index);
  }
  auto& tr = c3t3.triangulation();
  const auto cwp = tr.geom_traits().construct_weighted_point_3_object();
  for (const auto& [p, index] : pts) {
    const Tr::Vertex_handle v = tr.insert(cwp(p));
    if (v == Tr::Vertex_handle()) continue;
    c3t3.set_dimension(v, 2);
    c3t3.set_index(v, index);
  }
}

/// One Delaunay refinement at `size`; sliver optimisation only when `optimise`
/// (it dominates the cost, so the size search runs without it).
TetMesh mesh_once(const Domain& domain, const SurfaceMesh& surface, const TetrahedralizeOptions& o,
                  double size, bool optimise) {
  namespace p = CGAL::parameters;
  CGAL::get_default_random() = CGAL::Random(o.random_seed);
  const Criteria criteria(p::facet_angle = o.facet_angle_deg,
                          p::facet_size = o.facet_size_factor * size,
                          p::facet_distance = o.facet_distance_factor * size,
                          p::cell_radius_edge_ratio = o.radius_edge_bound, p::cell_size = size);
  C3t3 c3t3;
  seed(c3t3, domain, surface, o.facet_size_factor * size);
  // manifold(): the boundary of the complex must be a manifold surface (thin
  // parts otherwise yield boundary edges shared by four faces).
  CGAL::refine_mesh_3(c3t3, domain, criteria, p::no_perturb(), p::no_exude(), p::manifold());
  if (optimise && o.perturb)
    CGAL::perturb_mesh_3(c3t3, domain, p::sliver_bound = o.sliver_bound_deg);
  if (optimise && o.exude) CGAL::exude_mesh_3(c3t3, p::sliver_bound = o.sliver_bound_deg);

  TetMesh out;
  std::unordered_map<Tr::Vertex_handle, int> id;
  std::vector<Eigen::RowVector3d> pts;
  out.T.resize(static_cast<Eigen::Index>(c3t3.number_of_cells_in_complex()), 4);
  int t = 0;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c, ++t)
    for (int i = 0; i < 4; ++i) {
      const auto v = c->vertex(i);
      auto [it, inserted] = id.try_emplace(v, static_cast<int>(pts.size()));
      if (inserted) {
        const auto& q = c3t3.triangulation().point(v);
        pts.emplace_back(CGAL::to_double(q.x()), CGAL::to_double(q.y()), CGAL::to_double(q.z()));
      }
      out.T(t, i) = it->second;
    }
  out.V.resize(static_cast<Eigen::Index>(pts.size()), 3);
  for (size_t i = 0; i < pts.size(); ++i) out.V.row(static_cast<Eigen::Index>(i)) = pts[i];
  const Eigen::VectorXd vol = signed_tet_volumes(out.V, out.T);
  for (int e = 0; e < out.T.rows(); ++e)
    if (vol[e] < 0) std::swap(out.T(e, 2), out.T(e, 3));
  out.F = boundary_faces(out.T);
  return out;
}

}  // namespace

TetrahedralizeResult tetrahedralize_surface(const SurfaceMesh& surface,
                                            const TetrahedralizeOptions& o) {
  if ((o.cell_size <= 0.0 && o.target_tets < 1) || !(o.cell_size >= 0.0) ||
      !(o.facet_size_factor > 0.0) || !(o.facet_distance_factor > 0.0) ||
      !(o.facet_angle_deg > 0.0 && o.facet_angle_deg <= 30.0) || !(o.radius_edge_bound >= 2.0) ||
      !(o.sliver_bound_deg >= 0.0 && o.sliver_bound_deg < 70.0) || o.max_size_iterations < 1 ||
      !(o.count_tolerance > 0.0))
    throw ParameterError(
        "tetrahedralize_surface: need target_tets >= 1 or cell_size > 0, facet_angle_deg in (0, "
        "30], "
        "radius_edge_bound >= 2, sliver_bound_deg in [0, 70), positive factors, "
        "max_size_iterations >= 1");
  CgalMesh sm;
  if (!detail::to_cgal(surface, sm) || !CGAL::is_closed(sm))
    throw InputError("tetrahedralize_surface: the surface is not a closed manifold triangle mesh");
  const double volume = CGAL::Polygon_mesh_processing::volume(sm);
  if (!(volume > 0.0))
    throw InputError("tetrahedralize_surface: the surface encloses no positive volume (" +
                     std::to_string(volume) + "); is it oriented outward?");
  const Domain domain(sm);

  TetrahedralizeResult best;
  if (o.cell_size > 0.0) {
    best.mesh = mesh_once(domain, surface, o, o.cell_size, true);
    best.cell_size = o.cell_size;
    best.passes = 1;
  } else {
    // Size search without sliver optimisation (which changes the count only
    // slightly), then one optimised pass at the best size. Initial guess: a
    // regular tet of edge a has volume a^3 / (6 sqrt 2) and circumradius
    // a sqrt(6) / 4; refinement stops well below the bound, hence the factor.
    const double a = std::cbrt(6.0 * std::sqrt(2.0) * volume / o.target_tets);
    double size = a * std::sqrt(6.0) / 4.0 * 2.0;
    double best_err = INFINITY, best_size = size;
    for (int pass = 1; pass <= o.max_size_iterations; ++pass) {
      const double n = static_cast<double>(mesh_once(domain, surface, o, size, false).T.rows());
      const double err = std::abs(n / o.target_tets - 1.0);
      if (err < best_err) {
        best_err = err;
        best_size = size;
      }
      best.passes = pass;
      if (err <= o.count_tolerance || n == 0) break;
      // Count ~ size^-3 for volume-dominated meshes, flatter when the surface
      // dominates; the exponent 1/2 undershoots less on thin shapes.
      size *= std::pow(n / o.target_tets, 0.5);
    }
    best.mesh = mesh_once(domain, surface, o, best_size, true);
    best.cell_size = best_size;
    ++best.passes;
  }
  if (best.mesh.T.rows() == 0)
    throw InputError("tetrahedralize_surface: the mesher produced no tetrahedron (cell size " +
                     std::to_string(best.cell_size) + ")");
  // The boundary must be a closed manifold surface (the coarse surface nodes
  // and the collision surface rely on it): each directed edge exactly once,
  // its reverse exactly once.
  {
    std::map<std::pair<int, int>, int> directed;
    const MatX3i& F = best.mesh.F;
    for (int f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) ++directed[{F(f, k), F(f, (k + 1) % 3)}];
    for (const auto& [e, n] : directed) {
      const auto rev = directed.find({e.second, e.first});
      if (n != 1 || rev == directed.end() || rev->second != 1)
        throw InputError(
            "tetrahedralize_surface: the boundary of the tet mesh is not a closed manifold "
            "surface at the edge between nodes " +
            std::to_string(e.first) + " and " + std::to_string(e.second) + " (cell size " +
            std::to_string(best.cell_size) + "); try a smaller cell size or more tets");
    }
  }
  best.quality = tet_quality(best.mesh);
  return best;
}

}  // namespace icd::mesh
