#include <icd/mesh/io/detail/surface_builder.hpp>

#include <cmath>
#include <limits>

#include <icd/mesh/io/detail/input_error.hpp>

namespace icd::detail {

void SurfaceBuilder::reserve(int64_t vertices, int64_t polygons) {
  m_vertices.reserve(static_cast<size_t>(3 * vertices));
  m_triangles.reserve(static_cast<size_t>(3 * polygons));
  m_tri_polygon.reserve(static_cast<size_t>(polygons));
}

void SurfaceBuilder::add_vertex(double x, double y, double z, int64_t line) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    const char* what = (std::isnan(x) || std::isnan(y) || std::isnan(z)) ? "NaN" : "infinite";
    throw_input_error(
        m_source, line,
        "vertex " + std::to_string(num_vertices()) + " has a " + what + " coordinate");
  }
  if (num_vertices() >= std::numeric_limits<int32_t>::max())
    throw_input_error(m_source, line, "too many vertices (more than 2^31 - 1)");
  m_vertices.push_back(x);
  m_vertices.push_back(y);
  m_vertices.push_back(z);
}

void SurfaceBuilder::fail_polygon(int64_t polygon, int64_t line, const std::string& what) const {
  throw_input_error(m_source, line, "face " + std::to_string(polygon) + ": " + what);
}

void SurfaceBuilder::add_polygon(std::span<const int64_t> corners, int64_t line) {
  const int64_t polygon = m_polygons;
  if (corners.size() < 3)
    fail_polygon(polygon, line,
                 "has " + std::to_string(corners.size()) + " vertices; at least 3 are needed");
  for (const int64_t c : corners)
    if (c < 0 || c > std::numeric_limits<int32_t>::max())
      fail_polygon(polygon, line, "vertex index " + std::to_string(c) + " is out of range");
  if (m_triangles.size() / 3 + corners.size() - 2 >
      static_cast<size_t>(std::numeric_limits<int32_t>::max()))
    throw_input_error(m_source, line, "too many triangles (more than 2^31 - 1)");
  // Fan around the first corner: (c0, ck, ck+1).
  for (size_t k = 1; k + 1 < corners.size(); ++k) {
    m_triangles.push_back(static_cast<int32_t>(corners[0]));
    m_triangles.push_back(static_cast<int32_t>(corners[k]));
    m_triangles.push_back(static_cast<int32_t>(corners[k + 1]));
    m_tri_polygon.push_back(static_cast<int32_t>(polygon));
  }
  if (corners.size() > 3) ++m_triangulated;
  if (line >= 1) m_polygon_line.push_back(line);
  ++m_polygons;
}

SurfaceMesh SurfaceBuilder::finish(std::string format, ReadReport* report) {
  const int64_t nv = num_vertices();
  const int64_t nt = static_cast<int64_t>(m_tri_polygon.size());
  if (nv == 0) throw_input_error(m_source, "empty mesh: the file has no vertices");
  if (nt == 0) throw_input_error(m_source, "empty mesh: the file has no faces");
  for (int64_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const int32_t idx = m_triangles[3 * t + k];
      if (idx >= nv) {
        const int64_t polygon = m_tri_polygon[t];
        const int64_t line = m_polygon_line.empty() ? 0 : m_polygon_line[polygon];
        fail_polygon(polygon, line,
                     "vertex index " + std::to_string(idx) + " is out of range (the mesh has " +
                         std::to_string(nv) + " vertices)");
      }
    }
  SurfaceMesh mesh;
  mesh.V = Eigen::Map<const MatX3d>(m_vertices.data(), nv, 3);
  mesh.F = Eigen::Map<const MatX3i>(m_triangles.data(), nt, 3);
  if (m_triangulated > 0)
    m_notes.push_back(std::to_string(m_triangulated) +
                      " polygons with more than 3 vertices were fan-triangulated");
  if (report) {
    report->format = std::move(format);
    report->vertices = nv;
    report->polygons = m_polygons;
    report->triangles = nt;
    report->polygons_triangulated = m_triangulated;
    report->corners_welded = m_welded;
    report->notes = std::move(m_notes);
    report->warnings = std::move(m_warnings);
  }
  return mesh;
}

}  // namespace icd::detail
