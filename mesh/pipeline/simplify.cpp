// Garland-Heckbert placement solves a 3x3 system with CGAL's Eigen support.
#ifndef CGAL_EIGEN3_ENABLED
#define CGAL_EIGEN3_ENABLED
#endif

#include <icd/mesh/pipeline/simplify.hpp>

// GCC 12 reports a false -Wmaybe-uninitialized inside CGAL's Garland-Heckbert
// quadric code (an Eigen 4x4 matrix copied in an optional); not our code.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_filter.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include <cmath>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/pipeline/cgal_convert.hpp>

namespace icd::mesh {
namespace SMS = CGAL::Surface_mesh_simplification;
namespace PMP = CGAL::Polygon_mesh_processing;
using detail::CgalMesh;

SimplifyResult simplify_surface(const SurfaceMesh& input, const SimplifyOptions& options) {
  const int nf = static_cast<int>(input.F.rows());
  int target = options.target_faces;
  if (target < 0 || (target == 0 && !(options.target_ratio > 0.0 && options.target_ratio <= 1.0)))
    throw ParameterError(
        "simplify_surface: target_faces must be > 0, or 0 with target_ratio in (0, 1]");
  if (target == 0) target = static_cast<int>(std::lround(options.target_ratio * nf));
  if (target < 4)
    throw ParameterError("simplify_surface: target of " + std::to_string(target) +
                         " faces is below the 4 faces of a closed surface");
  SimplifyResult result;
  result.report.input_faces = nf;
  CgalMesh m;
  if (!detail::to_cgal(input, m))
    throw InputError(
        "simplify_surface: input is not a manifold, consistently oriented triangle mesh");
  // A collapse sequence can fold the surface into itself (the mesher then
  // fails or stalls): check, and retry with twice the faces, else keep the input.
  const CgalMesh original = m;
  for (int attempt = 0; nf > target; ++attempt) {
    if (attempt > 0) {
      m = original;
      target *= 2;
      ++result.report.self_intersection_retries;
      if (nf <= target) break;
    }
    using Policies = SMS::GarlandHeckbert_plane_policies<CgalMesh, detail::Kernel>;
    Policies gh(m);
    // A closed triangle mesh has E = 3F/2 edges; the predicate counts edges.
    const SMS::Count_stop_predicate<CgalMesh> stop(static_cast<std::size_t>(3 * target / 2) + 1);
    const auto np = CGAL::parameters::get_cost(gh.get_cost()).get_placement(gh.get_placement());
    result.report.collapsed_edges =
        options.bounded_normal_change
            ? SMS::edge_collapse(m, stop, np.filter(SMS::Bounded_normal_change_filter<>()))
            : SMS::edge_collapse(m, stop, np);
    m.collect_garbage();
    if (!options.check_self_intersections || !PMP::does_self_intersect(m)) break;
  }
  result.mesh = detail::from_cgal(m);
  result.report.output_faces = static_cast<int>(result.mesh.F.rows());
  return result;
}

}  // namespace icd::mesh
