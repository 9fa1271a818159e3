#include <icd/mesh/io/vtk_writer.hpp>

#include <cmath>
#include <cstdint>
#include <set>
#include <string>

#include <icd/mesh/io/atomic_write.hpp>
#include <icd/mesh/io/detail/number_format.hpp>
#include <icd/mesh/io/detail/xml_text.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd {
namespace {

constexpr int kVtkVertex = 1;
constexpr int kVtkTriangle = 5;
constexpr int kVtkTetra = 10;

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw ParameterError(path.string() + ": cannot write: " + what);
}

template <class Derived>
void check_finite(const std::filesystem::path& path, const Eigen::MatrixBase<Derived>& m,
                  const std::string& what) {
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    if (!m.row(i).allFinite())
      fail(path, what + " row " + std::to_string(i) + " has a NaN or infinite value");
}

template <class Derived>
void check_indices(const std::filesystem::path& path, const Eigen::MatrixBase<Derived>& cells,
                   Eigen::Index num_points, const std::string& what) {
  for (Eigen::Index i = 0; i < cells.rows(); ++i)
    for (Eigen::Index c = 0; c < cells.cols(); ++c)
      if (cells(i, c) < 0 || cells(i, c) >= num_points)
        fail(path, what + " " + std::to_string(i) + " has vertex index " +
                       std::to_string(cells(i, c)) + " outside [0, " + std::to_string(num_points) +
                       ")");
}

void check_point_data(const std::filesystem::path& path, std::span<const PointDataArray> arrays,
                      Eigen::Index num_points, std::set<std::string> names) {
  for (const PointDataArray& a : arrays) {
    if (a.name.empty()) fail(path, "a point-data array has an empty name");
    if (!names.insert(a.name).second)
      fail(path, "point-data array name '" + a.name + "' is used twice");
    if (a.values.rows() != num_points || a.values.cols() < 1)
      fail(path, "point-data array '" + a.name + "' is " + std::to_string(a.values.rows()) + " x " +
                     std::to_string(a.values.cols()) + "; expected " + std::to_string(num_points) +
                     " rows and at least 1 column");
    check_finite(path, a.values, "point-data array '" + a.name + "'");
  }
}

void append_array(std::string& out, const std::string& attrs, const auto& values, Eigen::Index rows,
                  Eigen::Index cols) {
  out += "        <DataArray " + attrs + " format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < rows; ++i) {
    out += "          ";
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (c) out += ' ';
      detail::append_number(out, values(i, c));
    }
    out += '\n';
  }
  out += "        </DataArray>\n";
}

void append_double_array(std::string& out, const std::string& name_attr,
                         const Eigen::Ref<const Eigen::MatrixXd>& values) {
  std::string attrs = "type=\"Float64\"" + name_attr;
  attrs += " NumberOfComponents=\"" + std::to_string(values.cols()) + "\"";
  append_array(
      out, attrs, [&](Eigen::Index i, Eigen::Index c) { return values(i, c); }, values.rows(),
      values.cols());
}

// Writes a whole UnstructuredGrid whose cells all have `corners` vertices and
// VTK type `cell_type`; cell(i, c) gives the vertex indices.
void write_grid(const std::filesystem::path& path, const Eigen::Ref<const MatX3d>& points,
                Eigen::Index num_cells, int corners, int cell_type, const auto& cell,
                std::span<const PointDataArray> point_data, const PointDataArray* extra) {
  std::string out;
  out.reserve(static_cast<size_t>(points.rows() * 64 + num_cells * 32));
  out += "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n";
  out += "  <UnstructuredGrid>\n";
  out += "    <Piece NumberOfPoints=\"" + std::to_string(points.rows()) + "\" NumberOfCells=\"" +
         std::to_string(num_cells) + "\">\n";
  if (!point_data.empty() || extra) {
    out += "      <PointData>\n";
    if (extra)
      append_double_array(out, " Name=\"" + detail::xml_escape(extra->name) + "\"", extra->values);
    for (const PointDataArray& a : point_data)
      append_double_array(out, " Name=\"" + detail::xml_escape(a.name) + "\"", a.values);
    out += "      </PointData>\n";
  }
  out += "      <Points>\n";
  append_double_array(out, " Name=\"Points\"", points);
  out += "      </Points>\n      <Cells>\n";
  append_array(
      out, "type=\"Int64\" Name=\"connectivity\"",
      [&](Eigen::Index i, Eigen::Index c) { return static_cast<int64_t>(cell(i, c)); }, num_cells,
      corners);
  append_array(
      out, "type=\"Int64\" Name=\"offsets\"",
      [&](Eigen::Index i, Eigen::Index) { return static_cast<int64_t>(corners * (i + 1)); },
      num_cells, 1);
  append_array(
      out, "type=\"UInt8\" Name=\"types\"",
      [&](Eigen::Index, Eigen::Index) { return static_cast<int64_t>(cell_type); }, num_cells, 1);
  out += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  write_file_atomically(path, out);
}

}  // namespace

void write_vtu_tet_mesh(const std::filesystem::path& path, const TetMesh& mesh,
                        std::span<const PointDataArray> point_data) {
  check_finite(path, mesh.V, "vertex");
  check_indices(path, mesh.T, mesh.V.rows(), "tet");
  check_point_data(path, point_data, mesh.V.rows(), {});
  write_grid(
      path, mesh.V, mesh.T.rows(), 4, kVtkTetra,
      [&](Eigen::Index i, Eigen::Index c) { return mesh.T(i, c); }, point_data, nullptr);
}

void write_vtu_surface_mesh(const std::filesystem::path& path, const SurfaceMesh& mesh,
                            std::span<const PointDataArray> point_data) {
  check_finite(path, mesh.V, "vertex");
  check_indices(path, mesh.F, mesh.V.rows(), "face");
  check_point_data(path, point_data, mesh.V.rows(), {});
  write_grid(
      path, mesh.V, mesh.F.rows(), 3, kVtkTriangle,
      [&](Eigen::Index i, Eigen::Index c) { return mesh.F(i, c); }, point_data, nullptr);
}

void write_vtu_sphere_set(const std::filesystem::path& path, const SphereSet& spheres,
                          std::span<const PointDataArray> point_data) {
  const Eigen::Index n = spheres.centers.rows();
  if (spheres.radii.size() != n)
    fail(path, "sphere set has " + std::to_string(n) + " centres but " +
                   std::to_string(spheres.radii.size()) + " radii");
  check_finite(path, spheres.centers, "sphere centre");
  for (Eigen::Index i = 0; i < n; ++i)
    if (!std::isfinite(spheres.radii[i]) || spheres.radii[i] < 0)
      fail(path, "sphere " + std::to_string(i) + " has radius " + std::to_string(spheres.radii[i]) +
                     "; radii must be finite and >= 0");
  check_point_data(path, point_data, n, {"radius"});
  const PointDataArray radius{"radius", spheres.radii};
  write_grid(
      path, spheres.centers, n, 1, kVtkVertex, [](Eigen::Index i, Eigen::Index) { return i; },
      point_data, &radius);
}

void write_pvd(const std::filesystem::path& path, std::span<const PvdEntry> entries) {
  std::string out = "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n";
  out += "  <Collection>\n";
  for (size_t i = 0; i < entries.size(); ++i) {
    const PvdEntry& e = entries[i];
    if (!std::isfinite(e.time))
      fail(path, "PVD entry " + std::to_string(i) + " has a non-finite time");
    if (e.file.empty()) fail(path, "PVD entry " + std::to_string(i) + " has an empty file name");
    out += "    <DataSet timestep=\"";
    detail::append_number(out, e.time);
    out += "\" group=\"\" part=\"0\" file=\"" + detail::xml_escape(e.file) + "\"/>\n";
  }
  out += "  </Collection>\n</VTKFile>\n";
  write_file_atomically(path, out);
}

}  // namespace icd
