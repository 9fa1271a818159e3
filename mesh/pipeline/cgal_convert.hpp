#pragma once
/// Internal to mesh/pipeline: CGAL kernel and mesh types, and conversions
/// between icd::SurfaceMesh (plain Eigen) and CGAL::Surface_mesh. Not part of
/// the public API: no header outside mesh/ may include it.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <cassert>
#include <cstddef>
#include <vector>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh::detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using CgalMesh = CGAL::Surface_mesh<Point>;

/// Closes the hole bounded by the border halfedge `h` with a minimal-area
/// triangulation of its loop, adding no vertex (PMP::triangulate_hole);
/// returns the number of faces added. Defined in repair.cpp, so that CGAL's
/// hole filling on this mesh type is compiled once in the library (the
/// sphere code's close_holes uses it too).
std::size_t fill_hole(CgalMesh& mesh, CgalMesh::Halfedge_index h);

/// Builds a Surface_mesh from a valid, manifold, consistently oriented
/// triangle mesh (vertex i of V becomes vertex i). Returns false when a face
/// cannot be added (non-manifold or inconsistent orientation).
inline bool to_cgal(const SurfaceMesh& in, CgalMesh& out) {
  out.clear();
  out.reserve(static_cast<CgalMesh::size_type>(in.V.rows()),
              static_cast<CgalMesh::size_type>(3 * in.F.rows() / 2 + 3),
              static_cast<CgalMesh::size_type>(in.F.rows()));
  for (Eigen::Index i = 0; i < in.V.rows(); ++i)
    out.add_vertex(Point(in.V(i, 0), in.V(i, 1), in.V(i, 2)));
  for (Eigen::Index f = 0; f < in.F.rows(); ++f) {
    const auto fd =
        out.add_face(CgalMesh::Vertex_index(in.F(f, 0)), CgalMesh::Vertex_index(in.F(f, 1)),
                     CgalMesh::Vertex_index(in.F(f, 2)));
    if (fd == CgalMesh::null_face()) return false;
  }
  return true;
}

/// Copies a triangle Surface_mesh (garbage allowed) into V, F with vertices
/// renumbered in index order.
inline SurfaceMesh from_cgal(const CgalMesh& m) {
  SurfaceMesh out;
  std::vector<int> id(m.num_vertices(), -1);  // num_vertices() counts removed ones too
  out.V.resize(static_cast<Eigen::Index>(m.number_of_vertices()), 3);
  int n = 0;
  for (auto v : m.vertices()) {
    const Point& p = m.point(v);
    out.V.row(n) << p.x(), p.y(), p.z();
    id[v.idx()] = n++;
  }
  out.F.resize(static_cast<Eigen::Index>(m.number_of_faces()), 3);
  int f = 0;
  for (auto fd : m.faces()) {
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(fd), m)) {
      assert(k < 3);
      out.F(f, k++) = id[v.idx()];
    }
    ++f;
  }
  return out;
}

}  // namespace icd::mesh::detail
