#pragma once
/// Internal: accumulates the vertices and polygons a reader parses, checks
/// them, fan-triangulates, and produces the SurfaceMesh and ReadReport.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <icd/mesh/io/read_report.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::detail {

/// Collects one mesh. Every error names `source`, and the line (text formats,
/// line >= 1) or the element index (binary formats, line = 0).
class SurfaceBuilder {
 public:
  explicit SurfaceBuilder(std::string_view source) : m_source(source) {}

  /// Reserves room; callers pass counts already checked against the file size.
  void reserve(int64_t vertices, int64_t polygons);
  /// Appends a vertex; throws InputError if a coordinate is NaN or infinite.
  void add_vertex(double x, double y, double z, int64_t line);
  /// Appends a polygon of `corners` (0-based indices, checked against the final
  /// vertex count in finish()); throws InputError for fewer than 3 corners or
  /// an index outside [0, INT32_MAX].
  void add_polygon(std::span<const int64_t> corners, int64_t line);
  /// Number of vertices added so far.
  int64_t num_vertices() const { return static_cast<int64_t>(m_vertices.size() / 3); }
  /// Number of polygons added so far.
  int64_t num_polygons() const { return m_polygons; }
  /// Adds a note to the report.
  void note(std::string text) { m_notes.push_back(std::move(text)); }
  /// Adds a warning to the report (data beyond the header's counts).
  void warn(std::string text) { m_warnings.push_back(std::move(text)); }
  /// Counts welded corners (STL).
  void add_welded(int64_t n) { m_welded += n; }

  /// Checks indices and emptiness, builds the mesh, fills `report` if non-null.
  SurfaceMesh finish(std::string format, ReadReport* report);

 private:
  [[noreturn]] void fail_polygon(int64_t polygon, int64_t line, const std::string& what) const;

  std::string m_source;
  std::vector<double> m_vertices;       // x, y, z per vertex
  std::vector<int32_t> m_triangles;     // 3 per triangle
  std::vector<int32_t> m_tri_polygon;   // source polygon of each triangle
  std::vector<int64_t> m_polygon_line;  // line of each polygon (text formats)
  int64_t m_polygons = 0;
  int64_t m_triangulated = 0;
  int64_t m_welded = 0;
  std::vector<std::string> m_notes;
  std::vector<std::string> m_warnings;
};

}  // namespace icd::detail
