#include <icd/mesh/io/vtk_writer.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include <icd/mesh/io/atomic_write.hpp>
#include <icd/mesh/io/detail/number_format.hpp>
#include <icd/mesh/io/detail/xml_text.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd {
namespace {

constexpr int kVtkVertex = 1;
constexpr int kVtkPolyVertex = 2;
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
                      Eigen::Index num_points, std::set<std::string> names,
                      const std::string& kind = "point-data") {
  for (const PointDataArray& a : arrays) {
    if (a.name.empty()) fail(path, "a " + kind + " array has an empty name");
    if (!names.insert(a.name).second)
      fail(path, kind + " array name '" + a.name + "' is used twice");
    if (a.values.rows() != num_points || a.values.cols() < 1)
      fail(path, kind + " array '" + a.name + "' is " + std::to_string(a.values.rows()) + " x " +
                     std::to_string(a.values.cols()) + "; expected " + std::to_string(num_points) +
                     " rows and at least 1 column");
    check_finite(path, a.values, kind + " array '" + a.name + "'");
  }
}

// One DataArray: its XML attributes (type, Name, NumberOfComponents) and its
// values, value(i, c) for i < rows, c < cols, converted to T when binary.
// Binary arrays: each block (UInt64 byte count + values) is kept apart and
// its DataArray gets a placeholder offset, filled in by place_blocks.
using Blocks = std::vector<std::string>;

std::string offset_placeholder(size_t k) { return "@ICD_OFFSET_" + std::to_string(k) + "@"; }

// The order of the blocks in the appended data, and their offsets. meshio 5
// converts raw appended data to base64 array by array, in data order, and
// finds each array by its original offset among attributes it already
// rewrote to base64 offsets: if a rewritten offset equals a later array's
// original offset, it reads the wrong array. Any order is valid VTK, so pick
// the first (identity first) without such a collision.
std::vector<uint64_t> place_blocks(const Blocks& blocks, std::vector<size_t>& order) {
  order.resize(blocks.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::vector<uint64_t> offset(blocks.size());
  do {
    uint64_t raw = 0, b64 = 0;
    std::vector<uint64_t> rewritten;
    bool clash = false;
    for (const size_t k : order) {
      offset[k] = raw;
      for (const uint64_t r : rewritten) clash |= r == raw;
      rewritten.push_back(b64);
      raw += blocks[k].size();
      b64 += 4 * ((blocks[k].size() + 2) / 3);
    }
    if (!clash) return offset;
  } while (std::next_permutation(order.begin(), order.end()));
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;  // none found (never seen): identity
  uint64_t raw = 0;
  for (size_t k = 0; k < order.size(); ++k) offset[k] = raw, raw += blocks[k].size();
  return offset;
}

// One DataArray: its XML attributes (type, Name, NumberOfComponents) and its
// values, value(i, c) for i < rows, c < cols, converted to T when binary.
template <class T, class Value>
void append_array(std::string& out, Blocks* blocks, const std::string& attrs,
                  const Value& value, Eigen::Index rows, Eigen::Index cols) {
  if (blocks) {
    // Raw appended block: UInt64 byte count, then the values, little-endian
    // (the only byte order of the machines we build on; checked below).
    static_assert(std::endian::native == std::endian::little);
    out += "        <DataArray " + attrs + " format=\"appended\" offset=\"" +
           offset_placeholder(blocks->size()) + "\"/>\n";
    std::string b;
    const uint64_t bytes = static_cast<uint64_t>(rows * cols) * sizeof(T);
    b.reserve(sizeof bytes + bytes);
    b.append(reinterpret_cast<const char*>(&bytes), sizeof bytes);
    for (Eigen::Index i = 0; i < rows; ++i)
      for (Eigen::Index c = 0; c < cols; ++c) {
        const T v = static_cast<T>(value(i, c));
        b.append(reinterpret_cast<const char*>(&v), sizeof v);
      }
    blocks->push_back(std::move(b));
    return;
  }
  out += "        <DataArray " + attrs + " format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < rows; ++i) {
    out += "          ";
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (c) out += ' ';
      detail::append_number(out, value(i, c));
    }
    out += '\n';
  }
  out += "        </DataArray>\n";
}

void append_double_array(std::string& out, Blocks* appended, const std::string& name,
                         const Eigen::Ref<const Eigen::MatrixXd>& values) {
  const std::string attrs = "type=\"Float64\" Name=\"" + detail::xml_escape(name) +
                            "\" NumberOfComponents=\"" + std::to_string(values.cols()) + "\"";
  append_array<double>(
      out, appended, attrs, [&](Eigen::Index i, Eigen::Index c) { return values(i, c); },
      values.rows(), values.cols());
}

// Writes a whole UnstructuredGrid whose cells all have `corners` vertices and
// VTK type `cell_type`; cell(i, c) gives the vertex indices.
void write_grid(const std::filesystem::path& path, const Eigen::Ref<const MatX3d>& points,
                Eigen::Index num_cells, int corners, int cell_type, const auto& cell,
                std::span<const PointDataArray> point_data, const PointDataArray* extra,
                const VtuOptions& options) {
  check_point_data(path, options.cell_data, num_cells, {}, "cell-data");
  const bool binary = options.encoding == VtuEncoding::Binary;
  std::string out;
  Blocks blocks;
  Blocks* app = binary ? &blocks : nullptr;
  out.reserve(static_cast<size_t>(binary ? 4096 : points.rows() * 64 + num_cells * 32));
  out += "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\"";
  out += binary ? " header_type=\"UInt64\">\n" : ">\n";
  out += "  <UnstructuredGrid>\n";
  if (!std::isnan(options.time)) {
    if (!std::isfinite(options.time)) fail(path, "the time (TimeValue) is infinite");
    out += "    <FieldData>\n      <DataArray type=\"Float64\" Name=\"TimeValue\" "
           "NumberOfTuples=\"1\" format=\"ascii\">";
    detail::append_number(out, options.time);
    out += "</DataArray>\n    </FieldData>\n";
  }
  out += "    <Piece NumberOfPoints=\"" + std::to_string(points.rows()) + "\" NumberOfCells=\"" +
         std::to_string(num_cells) + "\">\n";
  if (!point_data.empty() || extra) {
    out += "      <PointData>\n";
    if (extra) append_double_array(out, app, extra->name, extra->values);
    for (const PointDataArray& a : point_data) append_double_array(out, app, a.name, a.values);
    out += "      </PointData>\n";
  }
  if (!options.cell_data.empty()) {
    out += "      <CellData>\n";
    for (const PointDataArray& a : options.cell_data)
      append_double_array(out, app, a.name, a.values);
    out += "      </CellData>\n";
  }
  out += "      <Points>\n";
  append_double_array(out, app, "Points", points);
  out += "      </Points>\n      <Cells>\n";
  const auto conn = [&](Eigen::Index i, Eigen::Index c) { return static_cast<int64_t>(cell(i, c)); };
  const auto offs = [&](Eigen::Index i, Eigen::Index) {
    return static_cast<int64_t>(corners * (i + 1));
  };
  // Binary: 32-bit indices when they fit (a third less than 64-bit for a
  // triangle mesh); ASCII keeps Int64 (the asset bundles' format).
  if (binary && static_cast<int64_t>(num_cells) * corners < INT32_MAX) {
    append_array<int32_t>(out, app, "type=\"Int32\" Name=\"connectivity\"", conn, num_cells,
                          corners);
    append_array<int32_t>(out, app, "type=\"Int32\" Name=\"offsets\"", offs, num_cells, 1);
  } else {
    append_array<int64_t>(out, app, "type=\"Int64\" Name=\"connectivity\"", conn, num_cells,
                          corners);
    append_array<int64_t>(out, app, "type=\"Int64\" Name=\"offsets\"", offs, num_cells, 1);
  }
  append_array<uint8_t>(
      out, app, "type=\"UInt8\" Name=\"types\"",
      [&](Eigen::Index, Eigen::Index) { return static_cast<int64_t>(cell_type); }, num_cells, 1);
  out += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n";
  if (binary) {
    // "_" starts the data; the newline after it is part of the format as
    // readers expect it (meshio strips the last one).
    std::vector<size_t> order;
    const std::vector<uint64_t> offset = place_blocks(blocks, order);
    for (size_t k = 0; k < blocks.size(); ++k) {
      const std::string key = " offset=\"" + offset_placeholder(k) + "\"";
      out.replace(out.find(key), key.size(), " offset=\"" + std::to_string(offset[k]) + "\"");
    }
    out += "  <AppendedData encoding=\"raw\">\n   _";
    for (const size_t k : order) out += blocks[k];
    out += "\n  </AppendedData>\n";
  }
  out += "</VTKFile>\n";
  write_file_atomically(path, out);
}

}  // namespace

void write_vtu_tet_mesh(const std::filesystem::path& path, const TetMesh& mesh,
                        std::span<const PointDataArray> point_data, const VtuOptions& options) {
  check_finite(path, mesh.V, "vertex");
  check_indices(path, mesh.T, mesh.V.rows(), "tet");
  check_point_data(path, point_data, mesh.V.rows(), {});
  write_grid(
      path, mesh.V, mesh.T.rows(), 4, kVtkTetra,
      [&](Eigen::Index i, Eigen::Index c) { return mesh.T(i, c); }, point_data, nullptr, options);
}

void write_vtu_surface_mesh(const std::filesystem::path& path, const SurfaceMesh& mesh,
                            std::span<const PointDataArray> point_data,
                            const VtuOptions& options) {
  check_finite(path, mesh.V, "vertex");
  check_indices(path, mesh.F, mesh.V.rows(), "face");
  check_point_data(path, point_data, mesh.V.rows(), {});
  write_grid(
      path, mesh.V, mesh.F.rows(), 3, kVtkTriangle,
      [&](Eigen::Index i, Eigen::Index c) { return mesh.F(i, c); }, point_data, nullptr, options);
}

void write_vtu_sphere_set(const std::filesystem::path& path, const SphereSet& spheres,
                          std::span<const PointDataArray> point_data,
                          const VtuOptions& options) {
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
  if (n == 0) {
    // No spheres: one poly-vertex cell of no points. A grid of no cells is
    // valid VTK, but readers such as meshio 5 fail on it (IndexError); an
    // empty poly-vertex is a valid empty cell that ParaView and meshio accept.
    // Written as ASCII: meshio 5 misreads empty arrays in appended binary.
    VtuOptions ascii = options;
    ascii.encoding = VtuEncoding::Ascii;
    write_grid(
        path, spheres.centers, 1, 0, kVtkPolyVertex, [](Eigen::Index, Eigen::Index) { return 0; },
        point_data, &radius, ascii);
    return;
  }
  write_grid(
      path, spheres.centers, n, 1, kVtkVertex, [](Eigen::Index i, Eigen::Index) { return i; },
      point_data, &radius, options);
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
    if (e.part < 0) fail(path, "PVD entry " + std::to_string(i) + " has a negative part");
    out += "    <DataSet timestep=\"";
    detail::append_number(out, e.time);
    out += "\" group=\"\" part=\"" + std::to_string(e.part) + "\" file=\"" + detail::xml_escape(e.file) + "\"/>\n";
  }
  out += "  </Collection>\n</VTKFile>\n";
  write_file_atomically(path, out);
}

}  // namespace icd
