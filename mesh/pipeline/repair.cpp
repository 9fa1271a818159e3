// Hole fairing needs CGAL's Eigen-based sparse solver.
#ifndef CGAL_EIGEN3_ENABLED
#define CGAL_EIGEN3_ENABLED
#endif

#include <icd/mesh/pipeline/repair.hpp>

#include <CGAL/alpha_wrap_3.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/repair_self_intersections.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/mesh_stats.hpp>
#include <icd/mesh/pipeline/cgal_convert.hpp>
#include <icd/mesh/pipeline/hausdorff.hpp>

namespace icd::mesh {
namespace PMP = CGAL::Polygon_mesh_processing;
using detail::CgalMesh;
using detail::Point;

namespace {

std::string fmt_point(const Eigen::RowVector3d& p) {
  std::ostringstream s;
  s.precision(6);
  s << "(" << p[0] << ", " << p[1] << ", " << p[2] << ")";
  return s.str();
}

std::string fmt_point(const Point& p) { return fmt_point(Eigen::RowVector3d(p.x(), p.y(), p.z())); }

double signed_volume(const CgalMesh& m) {
  double vol = 0.0;
  for (auto f : m.faces()) {
    auto h = m.halfedge(f);
    const Point &a = m.point(m.source(h)), &b = m.point(m.target(h)),
                &c = m.point(m.target(m.next(h)));
    vol += CGAL::scalar_product(a - CGAL::ORIGIN,
                                CGAL::cross_product(b - CGAL::ORIGIN, c - CGAL::ORIGIN)) /
           6.0;
  }
  return vol;
}

/// Boundary loops: (number of edges, diameter, a halfedge on it).
struct Loop {
  int edges = 0;
  double diameter = 0.0;
  CgalMesh::Halfedge_index h;
};

std::vector<Loop> boundary_loops(CgalMesh& m) {
  std::vector<CgalMesh::Halfedge_index> starts;
  PMP::extract_boundary_cycles(m, std::back_inserter(starts));
  std::vector<Loop> loops;
  for (auto h0 : starts) {
    std::vector<Point> pts;
    for (auto h : CGAL::halfedges_around_face(h0, m)) pts.push_back(m.point(m.source(h)));
    Loop l;
    l.edges = static_cast<int>(pts.size());
    l.h = h0;
    for (size_t i = 0; i < pts.size(); ++i)
      for (size_t j = i + 1; j < pts.size(); ++j)
        l.diameter = std::max(l.diameter, std::sqrt(CGAL::squared_distance(pts[i], pts[j])));
    loops.push_back(l);
  }
  return loops;
}

/// A refusal that alpha wrapping can replace; cause as RepairReport::wrap_cause.
class Wrappable : public InputError {
 public:
  Wrappable(int cause_, const std::string& message) : InputError(message), cause(cause_) {}
  int cause;
};

}  // namespace

std::size_t detail::fill_hole(CgalMesh& mesh, CgalMesh::Halfedge_index h) {
  std::vector<CgalMesh::Face_index> patch;
  PMP::triangulate_hole(mesh, h, std::back_inserter(patch));
  return patch.size();
}

RepairOptions::Wrap parse_wrap(const std::string& name, const std::string& field) {
  for (auto w : {RepairOptions::Wrap::never, RepairOptions::Wrap::fallback,
                 RepairOptions::Wrap::always})
    if (name == to_string(w)) return w;
  throw ParameterError(field + ": must be never, fallback or always, got '" + name + "'");
}

const char* to_string(RepairOptions::Wrap wrap) {
  switch (wrap) {
    case RepairOptions::Wrap::never:
      return "never";
    case RepairOptions::Wrap::fallback:
      return "fallback";
    case RepairOptions::Wrap::always:
      return "always";
  }
  return "?";
}

std::string RepairReport::to_string() const {
  std::ostringstream s;
  s << "input " << input_vertices << " vertices, " << input_faces << " faces\n";
  if (merged_duplicate_vertices)
    s << "merged duplicate vertices: " << merged_duplicate_vertices << "\n";
  if (removed_degenerate_faces)
    s << "removed degenerate faces: " << removed_degenerate_faces << "\n";
  if (removed_duplicate_faces) s << "removed duplicate faces: " << removed_duplicate_faces << "\n";
  if (removed_unreferenced_vertices)
    s << "removed unreferenced vertices: " << removed_unreferenced_vertices << "\n";
  if (reoriented_faces) s << "re-oriented faces: " << reoriented_faces << "\n";
  if (reversed_to_outward) s << "reversed to face outward\n";
  if (holes_filled)
    s << "filled holes: " << holes_filled << " (" << hole_faces_added << " faces)\n";
  if (split_nonmanifold_vertices)
    s << "split non-manifold vertices: " << split_nonmanifold_vertices
      << " (copies moved 1 % into their own fan)\n";
  if (largest_hole_filled > 0.1)
    s << "WARNING: filled a hole spanning " << 100.0 * largest_hole_filled
      << " % of the bounding-box diagonal: check the patch\n";
  if (self_intersections_autorefined)
    s << "resolved self-intersections by autorefinement: " << self_intersections_autorefined
      << " face pair(s); " << 100.0 * area_removed_inside
      << " % of the area lay inside the solid and was removed\n";
  if (self_intersections_repaired) {
    s << "repaired self-intersections locally: " << self_intersections_repaired
      << " face pair(s); area change " << 100.0 * area_change << " %, volume change "
      << 100.0 * volume_change << " %\n";
    if (std::max(std::abs(area_change), std::abs(volume_change)) > 0.005)
      s << "WARNING: the repair changed the surface by more than 0.5 %\n";
  }
  if (wrap_cause) {
    static const char* why[] = {"", "a non-manifold edge", "self-intersections that repair could not resolve",
                                "--wrap always",
                                "the mesher failed at every size on the repaired surface",
                                "parts of the repaired surface in near contact: the mesher would "
                                "refine between them"};
    s << (wrap_cause == 3 ? "" : "WARNING: ") << "rebuilt the surface by alpha wrapping ("
      << why[wrap_cause] << "; alpha " << wrap_alpha
      << " of the diagonal): every point of it lies within " << 100.0 * wrap_distance
      << " % of the diagonal of the input (parts of the input inside it are dropped; --wrap never refuses instead)\n";
    if (input_volume > 0.0) {
      const double change = volume / input_volume - 1.0;
      s << (std::abs(change) > 0.05 ? "WARNING: " : "")
        << "the wrap changes the enclosed volume by " << std::showpos << 100.0 * change
        << std::noshowpos << " % (the input encloses " << input_volume
        << (change > 0.05 ? "; the wrap fills holes, tunnels and gaps narrower than alpha" : "")
        << ")\n";
    }
  }
  s << "output " << output_vertices << " vertices, " << output_faces << " faces, " << components
    << " component(s), volume " << volume << "\n";
  return s.str();
}

RepairResult repair_surface(const SurfaceMesh& input, const RepairOptions& options,
                            const std::string& name) {
  if (options.max_hole_edges < 0 || !(options.max_hole_diameter >= 0.0) ||
      !(options.max_surface_change >= 0.0) ||
      !(options.min_volume_fraction >= 0.0) || !(options.wrap_alpha > 0.0) ||
      !(options.wrap_offset >= 0.0) || !(options.max_wrap_distance >= 0.0))
    throw ParameterError(
        "repair_surface: max_hole_edges, max_hole_diameter, min_volume_fraction, wrap_offset "
        "and max_wrap_distance must be >= 0, wrap_alpha > 0");
  RepairResult result;
  RepairReport& rep = result.report;
  const int nv = static_cast<int>(input.V.rows());
  const int nf = static_cast<int>(input.F.rows());
  rep.input_vertices = nv;
  rep.input_faces = nf;
  if (nv < 4 || nf < 4)
    throw InputError(name + ": " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                     " faces cannot bound a volume");
  for (int i = 0; i < nv; ++i)
    if (!input.V.row(i).allFinite())
      throw InputError(name + ": vertex " + std::to_string(i) + " has a non-finite coordinate");
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      if (input.F(f, k) < 0 || input.F(f, k) >= nv)
        throw InputError(name + ": face " + std::to_string(f) + " refers to vertex " +
                         std::to_string(input.F(f, k)) + ", outside [0, " + std::to_string(nv) +
                         ")");

  // 1. Merge exactly duplicated vertices (first occurrence wins).
  std::map<std::array<double, 3>, int> unique;
  std::vector<int> remap(nv);
  std::vector<int> first_of;  // new index -> an original index
  for (int i = 0; i < nv; ++i) {
    const auto [it, inserted] = unique.try_emplace({input.V(i, 0), input.V(i, 1), input.V(i, 2)},
                                                   static_cast<int>(first_of.size()));
    if (inserted) first_of.push_back(i);
    remap[i] = it->second;
  }
  rep.merged_duplicate_vertices = nv - static_cast<int>(first_of.size());

  // 2. Drop faces with a repeated vertex, and repeated faces (same vertex set).
  std::vector<std::array<int, 3>> faces;
  std::vector<int> face_origin;  // output face -> input face
  std::set<std::array<int, 3>> seen;
  for (int f = 0; f < nf; ++f) {
    std::array<int, 3> t{remap[input.F(f, 0)], remap[input.F(f, 1)], remap[input.F(f, 2)]};
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++rep.removed_degenerate_faces;
      continue;
    }
    std::array<int, 3> key = t;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) {
      ++rep.removed_duplicate_faces;
      continue;
    }
    faces.push_back(t);
    face_origin.push_back(f);
  }

  // 3. Drop unreferenced vertices.
  std::vector<int> used(first_of.size(), -1);
  std::vector<Point> points;
  for (auto& t : faces)
    for (int& v : t) {
      if (used[v] < 0) {
        used[v] = static_cast<int>(points.size());
        const int o = first_of[v];
        points.emplace_back(input.V(o, 0), input.V(o, 1), input.V(o, 2));
      }
      v = used[v];
    }
  rep.removed_unreferenced_vertices = static_cast<int>(first_of.size() - points.size());
  std::vector<int> original_vertex(points.size());
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v] >= 0) original_vertex[used[v]] = first_of[v];
  if (points.size() < 4 || faces.size() < 4)
    throw InputError(name + ": only " + std::to_string(faces.size()) +
                     " non-degenerate faces remain; the surface cannot bound a volume");

  // 4. Flat input (zero volume): all vertices in one plane.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const Point& p : points) {
    const Eigen::Vector3d x(p.x(), p.y(), p.z());
    mean += x;
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  mean /= static_cast<double>(points.size());
  const double diag = (hi - lo).norm();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Point& p : points) {
    const Eigen::Vector3d x = Eigen::Vector3d(p.x(), p.y(), p.z()) - mean;
    cov += x * x.transpose();
  }
  cov /= static_cast<double>(points.size());
  const double thickness = std::sqrt(
      std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues()[0]));
  if (!(thickness > 1e-9 * diag))
    throw InputError(name + ": zero volume: all " + std::to_string(points.size()) +
                     " vertices lie in one plane (thickness " + std::to_string(thickness) +
                     ", diagonal " + std::to_string(diag) + ")");

  // Steps 5-9 make a clean surface of the welded soup, or throw Wrappable
  // (what alpha wrapping can fix) or InputError (what it cannot: open holes).
  CgalMesh mesh;
  const auto clean_steps = [&]() {
    std::vector<Point> pts = points;
    // 5. Non-manifold edges (more than two faces).
    {
      std::map<std::pair<int, int>, std::vector<int>> edge_faces;
      for (size_t f = 0; f < faces.size(); ++f)
        for (int k = 0; k < 3; ++k)
          edge_faces[std::minmax(faces[f][k], faces[f][(k + 1) % 3])].push_back(static_cast<int>(f));
      int bad = 0;
      std::string first;
      for (const auto& [e, fs] : edge_faces)
        if (fs.size() > 2) {
          if (bad++ == 0) {
            std::ostringstream s;
            s << "non-manifold edge between input vertices " << original_vertex[e.first] << " "
              << fmt_point(Eigen::RowVector3d(pts[e.first].x(), pts[e.first].y(),
                                              pts[e.first].z()))
              << " and " << original_vertex[e.second] << " shared by " << fs.size()
              << " faces (input faces";
            for (int f : fs) s << " " << face_origin[f];
            s << ")";
            first = s.str();
          }
        }
      if (bad > 0)
        throw Wrappable(1, name + ": " + first +
                               (bad > 1 ? "; " + std::to_string(bad - 1) + " more" : ""));
    }

    // 6. Consistent orientation of the soup; it splits non-manifold vertices.
    std::vector<std::vector<std::size_t>> polygons(faces.size());
    for (size_t f = 0; f < faces.size(); ++f)
      polygons[f] = {static_cast<size_t>(faces[f][0]), static_cast<size_t>(faces[f][1]),
                     static_cast<size_t>(faces[f][2])};
    const std::vector<std::vector<std::size_t>> before = polygons;
    const size_t n_points = pts.size();
    PMP::orient_polygon_soup(pts, polygons);
    if (pts.size() != n_points) {
      // A vertex whose faces form separate fans (two surfaces touching at a
      // point, often made by the exact-duplicate merge above) was split into one
      // copy per fan. Each copy moves 1 % of the way towards the centroid of its
      // fan's other vertices, so that the fans no longer touch (a shared point
      // would count as a self-intersection) while the shape stays put.
      rep.split_nonmanifold_vertices = static_cast<int>(pts.size() - n_points);
      std::vector<Eigen::Vector3d> sum(pts.size() - n_points, Eigen::Vector3d::Zero());
      std::vector<int> count(pts.size() - n_points, 0);
      for (const auto& poly : polygons)
        for (std::size_t k = 0; k < poly.size(); ++k)
          if (poly[k] >= n_points)
            for (std::size_t j = 0; j < poly.size(); ++j)
              if (j != k) {
                const Point& q = pts[poly[j]];
                sum[poly[k] - n_points] += Eigen::Vector3d(q.x(), q.y(), q.z());
                ++count[poly[k] - n_points];
              }
      for (std::size_t i = n_points; i < pts.size(); ++i) {
        if (count[i - n_points] == 0) continue;
        const Eigen::Vector3d c = sum[i - n_points] / count[i - n_points];
        const Eigen::Vector3d x(pts[i].x(), pts[i].y(), pts[i].z());
        const Eigen::Vector3d y = x + 0.01 * (c - x);
        pts[i] = Point(y[0], y[1], y[2]);
      }
    }
    for (size_t f = 0; f < polygons.size(); ++f) {
      const auto& a = before[f];
      const auto& b = polygons[f];
      const bool same = (a[0] == b[0] && a[1] == b[1]) || (a[0] == b[1] && a[1] == b[2]) ||
                        (a[0] == b[2] && a[1] == b[0]);
      rep.reoriented_faces += same ? 0 : 1;
    }
    PMP::polygon_soup_to_polygon_mesh(pts, polygons, mesh);

    // 7. Geometrically degenerate faces (zero area, not caught by indices).
    {
      bool any = false;
      for (auto f : mesh.faces())
        if (PMP::is_degenerate_triangle_face(f, mesh)) any = true;
      if (any) {
        const auto n_before = mesh.number_of_faces();
        PMP::remove_degenerate_faces(mesh);
        mesh.collect_garbage();
        rep.removed_degenerate_faces += static_cast<int>(n_before - mesh.number_of_faces());
      }
    }

    // 8. Fill small holes.
    for (const Loop& l : boundary_loops(mesh)) {
      if (l.edges > options.max_hole_edges || l.diameter > options.max_hole_diameter * diag) continue;
      rep.largest_hole_filled = std::max(rep.largest_hole_filled, l.diameter / diag);
      std::size_t added = 0;
      if (options.fair_holes) {
        std::vector<CgalMesh::Face_index> patch;
        std::vector<CgalMesh::Vertex_index> new_vertices;
        PMP::triangulate_refine_and_fair_hole(mesh, l.h, std::back_inserter(patch),
                                              std::back_inserter(new_vertices));
        added = patch.size();
      } else {
        added = detail::fill_hole(mesh, l.h);
      }
      ++rep.holes_filled;
      rep.hole_faces_added += static_cast<int>(added);
    }
    {
      const std::vector<Loop> left = boundary_loops(mesh);
      if (!left.empty()) {
        const auto big = std::max_element(
            left.begin(), left.end(), [](const Loop& a, const Loop& b) { return a.edges < b.edges; });
        std::ostringstream s;
        s << name << ": open surface: " << left.size() << " boundary loop(s) remain after filling "
          << rep.holes_filled << " small hole(s); the largest has " << big->edges
          << " edges and diameter " << big->diameter << " = " << big->diameter / diag
          << " of the bounding-box diagonal (limits: --max-hole-edges " << options.max_hole_edges
          << ", --max-hole-diameter " << options.max_hole_diameter
          << " of the diagonal) and passes through " << fmt_point(mesh.point(mesh.source(big->h)));
        int need_edges = 0;
        double need_diameter = 0.0;
        for (const Loop& l : left) {
          need_edges = std::max(need_edges, l.edges);
          need_diameter = std::max(need_diameter, l.diameter / diag);
        }
        s << "; to fill every hole: --max-hole-edges " << std::max(need_edges, options.max_hole_edges)
          << " --max-hole-diameter "
          << std::max(std::ceil(need_diameter * 100.0 + 1e-9) / 100.0, options.max_hole_diameter);
        throw InputError(s.str());
      }
    }
    mesh.collect_garbage();

    // 9. Self-intersections: first CGAL's autorefinement (split the faces
    // along the intersections, drop the patches inside the solid, stitch: the
    // union of the overlapping parts, the enclosed region unchanged); then its
    // local repair (remove the faces around each intersection, re-fill), which
    // changes the shape: its area and volume change is measured and limited;
    // else refuse with the count and a location.
    if (options.check_self_intersections && PMP::does_self_intersect(mesh)) {
      // The autorefinement keeps the outside of outward surfaces: turn each
      // component with a negative signed volume (orient_to_bound_a_volume needs
      // a surface without self-intersections).
      double largest_component = 0.0, all_components = 0.0;
      {
        auto fcc = mesh.add_property_map<CgalMesh::Face_index, std::size_t>("f:cc").first;
        const std::size_t n = PMP::connected_components(mesh, fcc);
        std::vector<double> vol(n, 0.0);
        for (auto f : mesh.faces()) {
          auto h = mesh.halfedge(f);
          const Point &a = mesh.point(mesh.source(h)), &b = mesh.point(mesh.target(h)),
                      &c = mesh.point(mesh.target(mesh.next(h)));
          vol[fcc[f]] += CGAL::scalar_product(
              a - CGAL::ORIGIN, CGAL::cross_product(b - CGAL::ORIGIN, c - CGAL::ORIGIN));
        }
        for (double v : vol) {
          largest_component = std::max(largest_component, std::abs(v) / 6.0);
          all_components += std::abs(v) / 6.0;
        }
        std::vector<CgalMesh::Face_index> flip;
        for (auto f : mesh.faces())
          if (vol[fcc[f]] < 0) flip.push_back(f);
        mesh.remove_property_map(fcc);
        if (!flip.empty()) PMP::reverse_face_orientations(flip, mesh);
      }
      std::vector<std::pair<CgalMesh::Face_index, CgalMesh::Face_index>> pairs;
      PMP::self_intersections(mesh, std::back_inserter(pairs));
      const std::size_t found = pairs.size();
      const auto centroid = [](const CgalMesh& m, CgalMesh::Face_index f) {
        auto h = m.halfedge(f);
        return CGAL::centroid(m.point(m.source(h)), m.point(m.target(h)),
                              m.point(m.target(m.next(h))));
      };
      std::ostringstream where;
      where << "e.g. faces near " << fmt_point(centroid(mesh, pairs[0].first)) << " and "
            << fmt_point(centroid(mesh, pairs[0].second));
      const double area0 = PMP::area(mesh), volume0 = std::abs(signed_volume(mesh));
      const auto clean = [](CgalMesh& m) {
        return CGAL::is_closed(m) && CGAL::is_valid_polygon_mesh(m) && !PMP::does_self_intersect(m);
      };
      bool repaired = false;
      std::string local_result;
      if (options.autorefine) {
        CgalMesh trial = mesh;
        bool ok = false;
        try {
          ok = PMP::experimental::autorefine_and_remove_self_intersections(trial);
          trial.collect_garbage();
        } catch (const std::exception&) {  // CGAL failure: fall back to the local repair
          ok = false;
        }
        // The union encloses at least the largest component and at most all of
        // them: anything else means patches outside were dropped (measured: the
        // Chinese dragon's local folds left 18 faces).
        const double v = ok && clean(trial) ? std::abs(signed_volume(trial)) : 0.0;
        const double tol = options.max_surface_change;
        if (ok && trial.number_of_faces() > 0 && v >= (1.0 - tol) * largest_component &&
            v <= (1.0 + tol) * all_components) {
          rep.self_intersections_autorefined = static_cast<int>(found);
          rep.area_removed_inside = 1.0 - PMP::area(trial) / area0;
          mesh = std::move(trial);
          repaired = true;
        }
      }
      if (!repaired && options.remove_self_intersections) {
        CgalMesh trial = mesh;
        bool ok = false;
        try {
          PMP::experimental::remove_self_intersections(trial);
          trial.collect_garbage();
          ok = clean(trial);
        } catch (const std::exception&) {
          ok = false;
        }
        if (ok) {
          const double da = PMP::area(trial) / area0 - 1.0;
          const double dv = std::abs(signed_volume(trial)) / volume0 - 1.0;
          const double worst = std::max(std::abs(da), std::abs(dv));
          if (worst <= options.max_surface_change) {
            rep.self_intersections_repaired = static_cast<int>(found);
            rep.area_change = da;
            rep.volume_change = dv;
            mesh = std::move(trial);
            repaired = true;
          } else {
            std::ostringstream m;
            m << "; the local repair would change the area by " << 100.0 * da
              << " % and the volume by " << 100.0 * dv << " % (limit "
              << 100.0 * options.max_surface_change
              << " %, option --max-surface-change F accepts up to F, e.g. --max-surface-change "
              << std::ceil(worst * 100.0 + 1e-9) / 100.0 << ")";
            local_result = m.str();
          }
        } else {
          local_result = "; the local repair did not remove them";
        }
      }
      if (!repaired) {
        std::ostringstream s;
        s << name << ": the surface intersects itself: " << found << " intersecting face pair(s), "
          << where.str();
        if (options.autorefine) s << "; autorefinement failed or changed the enclosed volume";
        s << local_result;
        throw Wrappable(2, s.str());
      }
    }
  };
  const RepairReport before_clean = rep;
  std::string wrap_refusal;  // the refusal the wrap replaced
  if (options.wrap == RepairOptions::Wrap::always) {
    rep.wrap_cause = 3;
  } else {
    try {
      clean_steps();
    } catch (const Wrappable& e) {
      if (options.wrap == RepairOptions::Wrap::never)
        throw InputError(std::string(e.what()) +
                         "; option --wrap fallback rebuilds the surface by alpha wrapping "
                         "(a closed, manifold envelope within --wrap-alpha of the input)");
      rep = before_clean;
      rep.wrap_cause = e.cause;
      wrap_refusal = e.what();
    }
  }
  if (rep.wrap_cause != 0) {
    // The input's enclosed volume, when it is a closed, consistently oriented
    // surface (every edge in two faces that cross it in opposite directions):
    // the summary gives the volume the wrap adds.
    {
      SurfaceMesh soup;
      soup.V.resize(static_cast<Eigen::Index>(points.size()), 3);
      for (std::size_t v = 0; v < points.size(); ++v)
        soup.V.row(static_cast<Eigen::Index>(v)) << points[v].x(), points[v].y(), points[v].z();
      soup.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
      for (std::size_t f = 0; f < faces.size(); ++f)
        soup.F.row(static_cast<Eigen::Index>(f)) << faces[f][0], faces[f][1], faces[f][2];
      const SurfaceStats st = compute_surface_stats(soup);
      const bool closed =
          st.boundary_edges == 0 && st.nonmanifold_edges == 0 && st.inconsistent_edges == 0;
      rep.input_volume = closed ? std::abs(st.volume) : 0.0;
    }
    const double alpha = options.wrap_alpha * diag;
    const double offset = (options.wrap_offset > 0.0 ? options.wrap_offset : options.wrap_alpha / 30.0) * diag;
    std::vector<std::array<std::size_t, 3>> tris;
    tris.reserve(faces.size());
    for (const auto& t : faces)
      tris.push_back({static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]),
                      static_cast<std::size_t>(t[2])});
    mesh.clear();
    CGAL::alpha_wrap_3(points, tris, alpha, offset, mesh);
    mesh.collect_garbage();
    SurfaceMesh soup;
    soup.V.resize(static_cast<Eigen::Index>(points.size()), 3);
    for (std::size_t i = 0; i < points.size(); ++i)
      soup.V.row(static_cast<Eigen::Index>(i)) << points[i].x(), points[i].y(), points[i].z();
    soup.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
    for (std::size_t f = 0; f < faces.size(); ++f)
      soup.F.row(static_cast<Eigen::Index>(f)) << faces[f][0], faces[f][1], faces[f][2];
    const bool valid = mesh.number_of_faces() > 0 && CGAL::is_closed(mesh) &&
                       CGAL::is_valid_polygon_mesh(mesh);
    rep.wrap_alpha = options.wrap_alpha;
    rep.wrap_distance =
        valid ? approximate_one_sided_distance(detail::from_cgal(mesh), soup) / diag : INFINITY;
    if (!(rep.wrap_distance <= options.max_wrap_distance)) {
      std::ostringstream s;
      if (!wrap_refusal.empty()) s << wrap_refusal << "; ";
      else s << name << ": ";
      s << "alpha wrapping (--wrap, alpha " << options.wrap_alpha << " of the diagonal) ";
      if (valid)
        s << "reaches " << 100.0 * rep.wrap_distance
          << " % of the diagonal away from the input (limit " << 100.0 * options.max_wrap_distance
          << " %, --max-wrap-distance " << options.max_wrap_distance
          << "): a smaller --wrap-alpha, e.g. " << options.wrap_alpha / 2
          << ", follows it more closely; --max-wrap-distance "
          << std::ceil(rep.wrap_distance * 100.0 + 1e-9) / 100.0 << " accepts this wrap";
      else
        s << "gave no closed surface; try another --wrap-alpha";
      throw InputError(s.str());
    }
  }

  // 10. Outward orientation of each component.
  const double vol_before = signed_volume(mesh);
  PMP::orient_to_bound_a_volume(mesh);
  const double vol = signed_volume(mesh);
  rep.reversed_to_outward = (vol_before != vol);
  rep.volume = vol;
  if (!(vol > options.min_volume_fraction * diag * diag * diag))
    throw InputError(name + ": zero volume: the repaired surface encloses " + std::to_string(vol) +
                     " (bounding-box diagonal " + std::to_string(diag) + ")");
  {
    auto fcc = mesh.add_property_map<CgalMesh::Face_index, std::size_t>("f:cc").first;
    rep.components = static_cast<int>(PMP::connected_components(mesh, fcc));
    mesh.remove_property_map(fcc);
  }

  result.mesh = detail::from_cgal(mesh);
  rep.output_vertices = static_cast<int>(result.mesh.V.rows());
  rep.output_faces = static_cast<int>(result.mesh.F.rows());
  return result;
}

}  // namespace icd::mesh
