#include <icd/mesh/pipeline/tetrahedralize.hpp>

#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_error_code.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/Random.h>
#include <CGAL/exceptions.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/refine_mesh_3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <tuple>
#include <set>
#include <sstream>
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
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<Kernel, CgalMesh>;
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
    // A seed inside a protecting ball of a sharp feature is hidden: keep the ball.
    if (v == Tr::Vertex_handle() || tr.point(v).point() != p || tr.point(v).weight() != 0 ||
        (c3t3.in_dimension(v) >= 0 && c3t3.in_dimension(v) < 2))
      continue;
    c3t3.set_dimension(v, 2);
    c3t3.set_index(v, index);
  }
}

/// How mesh_once()'s refusal at the vertex cap begins (it crosses the
/// process boundary as an InputError message).
constexpr const char* kOverRefined = "the mesher over-refined";

/// One Delaunay refinement at `size`; sliver optimisation only when `optimise`
/// (it dominates the cost, so the size search runs without it). The
/// refinement stops at `max_vertices` (0: no cap) and throws an InputError
/// whose message begins with kOverRefined.
TetMesh mesh_once(const Domain& domain, const SurfaceMesh& surface, const TetrahedralizeOptions& o,
                  double size, bool optimise, std::size_t max_vertices) {
  namespace p = CGAL::parameters;
  CGAL::get_default_random() = CGAL::Random(o.random_seed);
  const Criteria criteria(p::facet_angle = o.facet_angle_deg,
                          p::facet_size = o.facet_size_factor * size,
                          p::facet_distance = o.facet_distance_factor * size,
                          p::cell_radius_edge_ratio = o.radius_edge_bound,
                          p::cell_size = o.interior_size_factor * size,
                          p::edge_size = o.facet_size_factor * size);
  C3t3 c3t3;
  // Sharp features (detected on the domain) are protected by balls first, as
  // make_mesh_3 does: without protection the refinement need not terminate
  // near small input angles (CAD parts stalled for minutes).
  if (o.feature_angle_deg > 0.0)
    CGAL::Mesh_3::internal::init_c3t3_with_features(c3t3, domain, criteria);
  seed(c3t3, domain, surface, o.facet_size_factor * size);
  // manifold(): the boundary of the complex must be a manifold surface (thin
  // parts otherwise yield boundary edges shared by four faces).
  CGAL::Mesh_error_code code = CGAL::CGAL_MESH_3_NO_ERROR;
  CGAL::refine_mesh_3(c3t3, domain, criteria, p::no_perturb(), p::no_exude(), p::manifold(),
                      p::mesh_3_options(p::maximal_number_of_vertices = max_vertices,
                                        p::pointer_to_error_code = &code));
  if (code == CGAL::CGAL_MESH_3_MAXIMAL_NUMBER_OF_VERTICES_REACHED)
    throw InputError(std::string(kOverRefined) + ": it reached " +
                      std::to_string(c3t3.triangulation().number_of_vertices()) +
                      " vertices, its cap (" + std::to_string(std::lround(o.over_refinement_factor)) +
                      " x what this size should give, at least " + std::to_string(o.min_vertex_cap) +
                      "): parts of the surface lie closer to each other than the cell size "
                      "(near-contact gaps, thin sheets)");
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

/// Empty when the boundary F of `m` is a closed manifold surface (each
/// directed edge exactly once, its reverse exactly once); else what is wrong.
std::string boundary_problem(const TetMesh& m) {
  std::map<std::pair<int, int>, int> directed;
  const MatX3i& F = m.F;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++directed[{F(f, k), F(f, (k + 1) % 3)}];
  for (const auto& [e, n] : directed) {
    const auto rev = directed.find({e.second, e.first});
    if (n != 1 || rev == directed.end() || rev->second != 1)
      return "the boundary of the tet mesh is not a closed manifold surface at the edge between "
             "nodes " +
             std::to_string(e.first) + " and " + std::to_string(e.second);
  }
  return "";
}

std::string serialize(const TetMesh& m) {
  ByteWriter w;
  w.mat(m.V);
  w.mat(m.T);
  w.mat(m.F);
  return w.take();
}

TetMesh deserialize(const std::string& bytes) {
  ByteReader r(bytes);
  TetMesh m;
  m.V = r.mat<MatX3d>();
  m.T = r.mat<MatX4i>();
  m.F = r.mat<MatX3i>();
  return m;
}

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}

}  // namespace

double initial_cell_size(double volume, int target_tets) {
  // A regular tet of edge a has volume a^3 / (6 sqrt 2) and circumradius a sqrt(6) / 4.
  const double a = std::cbrt(6.0 * std::sqrt(2.0) * volume / target_tets);
  return a * std::sqrt(6.0) / 4.0 * 2.0;
}

TetrahedralizeResult tetrahedralize_surface(const SurfaceMesh& surface,
                                            const TetrahedralizeOptions& o,
                                            const HeartbeatFn& heartbeat) {
  if ((o.cell_size <= 0.0 && o.target_tets < 1) || !(o.cell_size >= 0.0) ||
      !(o.facet_size_factor > 0.0) || !(o.facet_distance_factor > 0.0) ||
      !(o.facet_angle_deg > 0.0 && o.facet_angle_deg <= 30.0) || !(o.radius_edge_bound >= 2.0) ||
      !(o.sliver_bound_deg >= 0.0 && o.sliver_bound_deg < 70.0) || o.max_size_iterations < 1 ||
      !(o.count_tolerance > 0.0) || !(o.pass_share > 0.0 && o.pass_share <= 1.0) ||
      o.max_retries < 0 || !(o.feature_angle_deg >= 0.0 && o.feature_angle_deg < 180.0) ||
      !(o.limits.cpu_seconds > 0.0) || !(o.limits.memory_mb > 0.0) ||
      !(o.step_cleanup.target_ratio >= 0.0) ||
      !(o.interior_size_factor > 0.0 && o.interior_size_factor <= 1.0) ||
      !(o.over_refinement_factor >= 0.0) || o.min_vertex_cap < 0 || !(o.cpu_budget >= 0.0))
    throw ParameterError(
        "tetrahedralize_surface: need target_tets >= 1 or cell_size > 0, facet_angle_deg in (0, "
        "30], radius_edge_bound >= 2, sliver_bound_deg in [0, 70), positive factors, "
        "max_size_iterations >= 1, pass_share in (0, 1], max_retries >= 0, positive limits, step_cleanup.target_ratio >= 0, interior_size_factor in (0, 1], "
        "over_refinement_factor, min_vertex_cap and cpu_budget >= 0");
  CgalMesh sm;
  if (!detail::to_cgal(surface, sm) || !CGAL::is_closed(sm))
    throw InputError("tetrahedralize_surface: the surface is not a closed manifold triangle mesh");
  const double volume = CGAL::Polygon_mesh_processing::volume(sm);
  if (!(volume > 0.0))
    throw InputError("tetrahedralize_surface: the surface encloses no positive volume (" +
                     std::to_string(volume) + "); is it oriented outward?");
  const double diagonal = (surface.V.colwise().maxCoeff() - surface.V.colwise().minCoeff()).norm();
  const double max_size = 0.5 * diagonal;  // a larger circumradius bound changes nothing
  const double area = CGAL::Polygon_mesh_processing::area(sm);
  // The vertex cap of a pass at `size`: over_refinement_factor x the vertices
  // of regular tets whose circumradius is half the bound (as the initial guess
  // below) filling the volume, plus half the surface triangles of that edge.
  const auto vertex_cap = [&](double size) -> std::size_t {
    if (o.over_refinement_factor <= 0.0) return 0;
    const double a = size * 2.0 / std::sqrt(6.0);
    const double f = o.interior_size_factor;
    const double tets = volume / (a * a * a * f * f * f / (6.0 * std::sqrt(2.0)));
    const double faces = area / (a * a * std::sqrt(3.0) / 4.0);
    const double cap = o.over_refinement_factor * (tets / 5.0 + faces / 2.0);
    return static_cast<std::size_t>(std::min(1e9, std::max<double>(o.min_vertex_cap, cap)));
  };
  Domain domain(sm);
  TetrahedralizeResult res;
  if (o.feature_angle_deg > 0.0) {
    domain.detect_features(o.feature_angle_deg);
    std::vector<std::tuple<Domain::Curve_index, std::pair<Domain::Point_3, Domain::Index>,
                           std::pair<Domain::Point_3, Domain::Index>>>
        curves;
    domain.get_curves(std::back_inserter(curves));
    res.feature_curves = static_cast<int>(curves.size());
  }
  double spent = 0.0;  // CPU seconds of all passes
  const double budget = o.cpu_budget > 0.0 ? o.cpu_budget : o.limits.cpu_seconds;
  int retries_left = o.max_retries;
  std::string last_cause;
  bool last_over_refined = false;
  std::vector<std::string> failures;
  // One bounded pass; false (and a note) when it failed.
  const auto attempt = [&](double size, bool optimise, TetMesh& out) {
    res.step_cleanup = {};
    last_over_refined = false;
    StageLimits pl = o.limits;
    pl.cpu_seconds = std::min(budget - spent, o.pass_share * o.limits.cpu_seconds);
    if (pl.cpu_seconds < 0.5) {
      last_cause = budget < o.limits.cpu_seconds
                       ? "its share of " + fmt(budget) + " s of the stage's CPU-time limit of " +
                             fmt(o.limits.cpu_seconds) + " s (--time-limit) is used up"
                       : "the stage's CPU-time limit of " + fmt(o.limits.cpu_seconds) +
                             " s (--time-limit) is used up";
      return false;
    }
    ++res.passes;
    const std::string label = "pass " + std::to_string(res.passes) + " (cell size " + fmt(size) +
                              (optimise ? ", optimised" : "") + ")";
    const HeartbeatFn beat = [&](const std::string& s) {
      if (heartbeat) heartbeat(label + " " + s);
    };
    StageUsage u;
    try {
      const std::string bytes = run_bounded(
          "tetrahedralize", pl,
          [&] {
            TetMesh m = mesh_once(domain, surface, o, size, optimise, vertex_cap(size));
            if (m.T.rows() == 0) throw InputError("the mesher produced no tetrahedron");
            const std::string problem = boundary_problem(m);
            if (!problem.empty()) throw InputError(problem);
            StepCleanupReport cleanup;
            if (optimise) {
              cleanup = raise_stable_step(m, o.step_cleanup);
              if (!boundary_problem(m).empty())  // raise_stable_step keeps it: a bug if not
                throw InputError("the stable-step post-pass broke the boundary: " +
                                 boundary_problem(m));
            }
            ByteWriter w;
            w.pod(cleanup);
            return w.take() + serialize(m);
          },
          &u, beat);
      ByteReader r(bytes);
      res.step_cleanup = r.pod<StepCleanupReport>();
      out = deserialize(bytes.substr(sizeof(StepCleanupReport)));
    } catch (const ParameterError&) {
      throw;
    } catch (const InputError& e) {
      last_cause = e.what();
      last_over_refined = last_cause.rfind(kOverRefined, 0) == 0;
    } catch (const CGAL::Failure_exception&) {  // only without isolation
      last_cause = "stage 'tetrahedralize' failed inside CGAL (an internal check did not hold)";
    }
    spent += u.cpu_seconds;
    res.usage += u;
    if (out.T.rows() > 0) return true;
    ++res.failed_passes;
    if (last_over_refined) ++res.over_refined_passes;
    failures.push_back("cell size " + fmt(size) + ": " + last_cause);
    return false;
  };
  static constexpr double kNearby[] = {0.85, 1.15, 0.7, 1.3, 0.6, 1.5, 0.5, 1.7};
  // Tries `size`, then nearby sizes while retries are left. A pass stopped
  // by the vertex cap is retried once in all, at 1.5 x its size: runaway
  // refinement comes from the surface's shape (gaps, sheets thinner than
  // any size tried), not from the size, and a finer size only refines more.
  const auto attempt_near = [&](double size, bool optimise, TetMesh& out, double& used) {
    double prev = size;
    for (int k = -1; k < static_cast<int>(std::size(kNearby)); ++k) {
      used = k < 0 ? size : std::min(max_size, size * kNearby[k]);
      if (k >= 0 && last_over_refined) {
        if (res.over_refined_passes > 1) return false;
        used = std::min(max_size, prev * 1.5);
      }
      if (k >= 0) {
        if (retries_left-- <= 0) return false;
        res.notes.push_back("pass at cell size " + fmt(prev) + " failed (" +
                            last_cause + "); retrying at cell size " + fmt(used));
        if (heartbeat) heartbeat(res.notes.back());
      }
      prev = used;
      TetMesh m;
      if (attempt(used, optimise, m)) {
        out = std::move(m);
        return true;
      }
      if (budget - spent < 0.5) return false;
    }
    return false;
  };

  if (o.cell_size > 0.0) {
    double used = 0.0;
    if (attempt_near(o.cell_size, true, res.mesh, used)) res.cell_size = used;
  } else {
    // Size search without sliver optimisation (which changes the count only
    // slightly), then one optimised pass at the best size.
    double size = std::min(max_size, initial_cell_size(volume, o.target_tets));
    double best_err = INFINITY, best_size = 0.0;
    for (int pass = 1; pass <= o.max_size_iterations; ++pass) {
      TetMesh m;
      double used = 0.0;
      if (!attempt_near(size, false, m, used)) break;
      const double n = static_cast<double>(m.T.rows());
      const double err = std::abs(n / o.target_tets - 1.0);
      if (err < best_err) {
        best_err = err;
        best_size = used;
      }
      if (err <= o.count_tolerance) break;
      // Count ~ size^-3 for volume-dominated meshes, flatter when the surface
      // dominates; the exponent 1/2 undershoots less on thin shapes.
      size = std::min(max_size, used * std::pow(n / o.target_tets, 0.5));
      if (size == used) break;  // at the largest size: no coarser mesh exists
    }
    double used = 0.0;
    if (best_size > 0.0 && attempt_near(best_size, true, res.mesh, used)) res.cell_size = used;
  }
  if (res.mesh.T.rows() == 0) {
    std::ostringstream s;
    s << "tetrahedralize: the mesher failed in all " << res.passes << " pass(es)";
    for (const std::string& f : failures) s << "; " << f;
    if (failures.empty() && !last_cause.empty()) s << ": " << last_cause;
    if (res.over_refined_passes > 0 && res.over_refined_passes == res.failed_passes) {
      // Every pass ran into its vertex cap: walls or gaps thinner than any
      // cell of this size. Measured on the corpus' cheese (walls between its
      // holes down to 0.04 % of the diagonal): more tets (10,000, 20,000),
      // another cell size and a longer --time-limit over-refine too, so the
      // refusal names only what closes the thin parts.
      s << ". Cause: every pass over-refined: parts of the surface lie closer to each other "
           "than the cell size (thin walls between holes or tunnels, near-contact gaps, thin "
           "sheets), which other cell sizes, more tets or longer limits do not resolve. ";
      const double alpha = o.wrap_alpha > 0.0 ? std::min(1.0, 10.0 * o.wrap_alpha) : 0.0;
      const std::string a = alpha > 0.0 ? fmt(alpha) : "A";
      const std::string coarser =
          "a coarser alpha wrap, which closes the holes, tunnels and gaps narrower than alpha so "
          "that no thin wall is left: --wrap always --wrap-alpha " +
          a + " --max-wrap-distance " + a + " (alpha" +
          (alpha > 0.0 ? (o.wrapped_surface ? " 10 x this wrap's" : " 10 x --wrap-alpha") : "") +
          ", a fraction of the "
          "diagonal; such a wrap lies farther from the input than the default limit, 3 % of the "
          "diagonal, and fills the holes: the summary gives its distance and the volume it adds; "
          "a smaller alpha keeps more holes but may over-refine again)";
      if (o.wrapped_surface)
        s << "The option that fixes this: " << coarser;
      else
        s << "The options that fix this: --wrap always (mesh an alpha-wrapped surface instead: "
             "gaps narrower than --wrap-alpha are closed); when its mesher over-refines too "
             "(thin walls between holes or tunnels wider than alpha, which the wrap follows), "
          << coarser;
      throw InputError(s.str());
    }
    s << ". Options that change this: --coarse-tets N or --cell-size H (other sizes), "
         "--time-limit S and --memory-limit MB (the stage's limits), ";
    if (o.wrapped_surface)
      s << "--wrap-alpha A (this surface is already an alpha wrap: a larger alpha, a fraction "
           "of the diagonal, closes wider gaps and thickens the wrap of thin sheets, which "
           "stall the mesher; --max-wrap-distance F accepts a wrap up to F of the diagonal from "
           "the input, default 0.03)";
    else
      s << "--wrap always (mesh an alpha-wrapped surface instead: near-contact gaps narrower "
           "than --wrap-alpha, which can stall the mesher, are closed)";
    throw InputError(s.str());
  }
  if (res.failed_passes > 0 && heartbeat)
    heartbeat(std::to_string(res.failed_passes) + " pass(es) failed and were retried at nearby "
              "cell sizes; kept cell size " + fmt(res.cell_size));
  res.quality = tet_quality(res.mesh);
  return res;
}

}  // namespace icd::mesh
