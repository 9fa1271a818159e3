#include <icd/mesh/io/vtu_reader.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <string_view>
#include <utility>

#include <icd/mesh/io/detail/file_bytes.hpp>
#include <icd/mesh/io/detail/input_error.hpp>
#include <icd/mesh/io/detail/text_scan.hpp>
#include <icd/mesh/io/detail/xml_scanner.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd {
namespace {

using detail::Tag;
using detail::throw_input_error;
using detail::XmlScanner;

int64_t int_attribute(const XmlScanner& xml, const Tag& tag, std::string_view key) {
  const std::string* v = tag.find(key);
  if (!v) xml.fail(tag.begin, "<" + std::string(tag.name) + "> has no " + std::string(key));
  int64_t n = 0;
  if (detail::parse_int64(*v, n) != detail::NumberStatus::ok || n < 0)
    xml.fail(tag.begin,
             std::string(key) + "=" + detail::quote(*v) + " is not a non-negative integer");
  return n;
}

// A parsed DataArray: its values as doubles (floating types) or integers.
struct Array {
  std::string name;
  bool is_float = false;
  int64_t components = 1;
  std::vector<double> reals;
  std::vector<int64_t> ints;
  int64_t size() const {
    return is_float ? static_cast<int64_t>(reals.size()) : static_cast<int64_t>(ints.size());
  }
};

Array read_data_array(XmlScanner& xml, const Tag& tag) {
  Array a;
  if (const std::string* n = tag.find("Name")) a.name = *n;
  const std::string label = "DataArray '" + a.name + "'";
  const std::string* type = tag.find("type");
  if (!type) xml.fail(tag.begin, label + " has no type");
  static constexpr std::string_view ints[] = {"Int8",  "UInt8",  "Int16", "UInt16",
                                              "Int32", "UInt32", "Int64", "UInt64"};
  if (*type == "Float32" || *type == "Float64")
    a.is_float = true;
  else if (std::find(std::begin(ints), std::end(ints), *type) == std::end(ints))
    xml.fail(tag.begin, label + " has unknown type " + detail::quote(*type));
  const std::string* format = tag.find("format");
  if (format && *format != "ascii")
    xml.fail(tag.begin, label + " uses format " + detail::quote(*format) +
                            "; only format=\"ascii\" is supported");
  if (tag.find("NumberOfComponents")) {
    a.components = int_attribute(xml, tag, "NumberOfComponents");
    if (a.components < 1 || a.components > 1024)
      xml.fail(tag.begin, label + " has NumberOfComponents outside [1, 1024]");
  }
  if (tag.self_closing) return a;
  const std::string_view text = xml.text();
  const size_t close = text.find("</DataArray>", tag.end);
  if (close == std::string_view::npos) xml.fail(tag.begin, label + " is not closed");
  const std::string_view body = text.substr(tag.end, close - tag.end);
  {  // Reserve exactly (no growth by doubling): count the tokens first.
    size_t count = 0;
    for (size_t i = 0; i < body.size(); ++i)
      count += !detail::is_space(body[i]) && (i == 0 || detail::is_space(body[i - 1]));
    if (a.is_float)
      a.reals.reserve(count);
    else
      a.ints.reserve(count);
  }
  detail::TokenStream ts(body, xml.line_at(tag.end));
  std::string_view tok;
  while (ts.next(tok)) {
    if (a.is_float) {
      double v = 0;
      if (detail::parse_double(tok, v) != detail::NumberStatus::ok)
        xml.fail(tag.end, label + ": value " + detail::quote(tok) + " (line " +
                              std::to_string(ts.line_number()) + ") is not a number");
      if (!std::isfinite(v))
        xml.fail(tag.end, label + ": value " + std::to_string(a.reals.size()) + " (line " +
                              std::to_string(ts.line_number()) + ") is NaN or infinite");
      a.reals.push_back(v);
    } else {
      int64_t v = 0;
      if (detail::parse_int64(tok, v) != detail::NumberStatus::ok)
        xml.fail(tag.end, label + ": value " + detail::quote(tok) + " (line " +
                              std::to_string(ts.line_number()) + ") is not an integer");
      a.ints.push_back(v);
    }
  }
  if (a.size() % a.components != 0)
    xml.fail(tag.begin, label + " has " + std::to_string(a.size()) + " values, not a multiple of " +
                            std::to_string(a.components) + " components");
  xml.seek(close + 12);
  return a;
}

}  // namespace

VtuData read_vtu(const std::filesystem::path& path) {
  return parse_vtu(detail::read_file_bytes(path, file_limits::kVtu, "VTU file"), path.string());
}

VtuData parse_vtu(std::string_view bytes, std::string_view source) {
  XmlScanner xml(strip_utf8_bom(bytes), source);  // XML may start with a byte-order mark
  Tag tag;
  if (!xml.next(tag) || tag.name != "VTKFile")
    throw_input_error(source, "not a VTK XML file: no <VTKFile> element");
  const std::string* type = tag.find("type");
  if (!type || *type != "UnstructuredGrid")
    xml.fail(tag.begin, "VTKFile type is " +
                            (type ? detail::quote(*type) : std::string("missing")) +
                            "; expected 'UnstructuredGrid'");
  if (const std::string* c = tag.find("compressor"))
    xml.fail(tag.begin, "compressed VTU (" + *c + ") is not supported");
  int64_t num_points = -1, num_cells = -1;
  std::vector<std::string> sections;  // open elements inside the Piece
  Array points;
  bool have_points = false;
  std::vector<Array> cell_arrays, point_arrays;
  bool piece_closed = false;
  while (!piece_closed && xml.next(tag)) {
    if (tag.name == "AppendedData")
      xml.fail(tag.begin, "appended (binary) data is not supported; write format=\"ascii\"");
    if (tag.name == "Piece") {
      if (tag.closing) {
        piece_closed = true;
        continue;
      }
      if (num_points >= 0) xml.fail(tag.begin, "more than one <Piece> is not supported");
      num_points = int_attribute(xml, tag, "NumberOfPoints");
      num_cells = int_attribute(xml, tag, "NumberOfCells");
      constexpr int64_t max_count = std::numeric_limits<int32_t>::max();
      if (num_points > max_count || num_cells > max_count)
        xml.fail(tag.begin, "NumberOfPoints or NumberOfCells exceeds 2^31 - 1");
      continue;
    }
    if (num_points < 0) continue;  // before the Piece
    if (tag.name == "DataArray") {
      if (tag.closing) xml.fail(tag.begin, "unexpected </DataArray>");
      const std::string where = sections.empty() ? "" : sections.back();
      Array a = read_data_array(xml, tag);
      if (where == "Points") {
        if (have_points) xml.fail(tag.begin, "<Points> has more than one DataArray");
        points = std::move(a);
        have_points = true;
      } else if (where == "Cells") {
        cell_arrays.push_back(std::move(a));
      } else if (where == "PointData") {
        point_arrays.push_back(std::move(a));
      }  // CellData and FieldData are ignored.
      continue;
    }
    if (tag.self_closing) continue;
    if (tag.closing) {
      if (sections.empty() || sections.back() != tag.name)
        xml.fail(tag.begin, "unexpected </" + std::string(tag.name) + ">");
      sections.pop_back();
    } else {
      sections.emplace_back(tag.name);
    }
  }
  if (num_points < 0) throw_input_error(source, "no <Piece> element");
  if (!piece_closed) throw_input_error(source, "truncated file: <Piece> is not closed");
  bool file_closed = false;
  while (!file_closed && xml.next(tag)) {
    if (tag.name == "AppendedData")
      xml.fail(tag.begin, "appended (binary) data is not supported; write format=\"ascii\"");
    file_closed = tag.closing && tag.name == "VTKFile";
  }
  if (!file_closed) throw_input_error(source, "truncated file: no closing </VTKFile>");
  if (!have_points) throw_input_error(source, "the Piece has no <Points> DataArray");

  VtuData out;
  if (!points.is_float || points.components != 3 || points.size() != 3 * num_points)
    throw_input_error(source, "Points must be a 3-component float array of NumberOfPoints=" +
                                  std::to_string(num_points) + " rows (found " +
                                  std::to_string(points.size()) + " values)");
  out.points = Eigen::Map<const MatX3d>(points.reals.data(), num_points, 3);
  std::vector<double>().swap(points.reals);  // (peak memory: free each array once copied)
  Array* conn = nullptr;
  Array* offs = nullptr;
  Array* types = nullptr;
  for (Array& a : cell_arrays) {
    if (a.name == "connectivity") conn = &a;
    if (a.name == "offsets") offs = &a;
    if (a.name == "types") types = &a;
  }
  if (!conn || !offs || !types)
    throw_input_error(source, "<Cells> needs the DataArrays 'connectivity', 'offsets' and 'types'");
  for (const Array* a : {conn, offs, types})
    if (a->is_float || a->components != 1)
      throw_input_error(source,
                        "Cells DataArray '" + a->name + "' must be a one-component integer array");
  if (offs->size() != num_cells || types->size() != num_cells)
    throw_input_error(source, "NumberOfCells=" + std::to_string(num_cells) + " but 'offsets' has " +
                                  std::to_string(offs->size()) + " and 'types' " +
                                  std::to_string(types->size()) + " values");
  int64_t prev = 0;
  for (int64_t c = 0; c < num_cells; ++c) {
    const int64_t o = offs->ints[c];
    if (o <= prev || o > conn->size())
      throw_input_error(source, "cell " + std::to_string(c) + ": offset " + std::to_string(o) +
                                    " does not increase or exceeds the connectivity size " +
                                    std::to_string(conn->size()));
    prev = o;
    const int64_t t = types->ints[c];
    if (t < 0 || t > 255)
      throw_input_error(source, "cell " + std::to_string(c) + ": cell type " + std::to_string(t) +
                                    " is not a VTK cell type");
    out.types.push_back(static_cast<uint8_t>(t));
  }
  if (prev != conn->size())
    throw_input_error(source, "the last offset (" + std::to_string(prev) +
                                  ") differs from the connectivity size (" +
                                  std::to_string(conn->size()) + ")");
  int64_t cell = 0;
  for (int64_t k = 0; k < conn->size(); ++k) {
    while (offs->ints[cell] <= k) ++cell;
    const int64_t v = conn->ints[k];
    if (v < 0 || v >= num_points)
      throw_input_error(source, "cell " + std::to_string(cell) + ": vertex index " +
                                    std::to_string(v) + " is out of range (the file has " +
                                    std::to_string(num_points) + " points)");
  }
  out.connectivity = std::move(conn->ints);
  out.offsets = std::move(offs->ints);
  for (Array& a : point_arrays) {
    if (a.name.empty()) throw_input_error(source, "a PointData DataArray has no Name");
    if (!a.is_float) {
      a.reals.assign(a.ints.begin(), a.ints.end());
      a.is_float = true;
    }
    if (a.size() != num_points * a.components)
      throw_input_error(source, "PointData '" + a.name + "' has " + std::to_string(a.size()) +
                                    " values; expected " + std::to_string(num_points) + " x " +
                                    std::to_string(a.components));
    PointDataArray p;
    p.name = a.name;
    p.values.resize(num_points, a.components);
    for (int64_t i = 0; i < num_points; ++i)
      for (int64_t c = 0; c < a.components; ++c) p.values(i, c) = a.reals[i * a.components + c];
    out.point_data.push_back(std::move(p));
  }
  return out;
}

namespace {

// Checks that every cell has type `type` and `corners` vertices; returns the
// #cells x corners index matrix.
template <class Mat>
Mat cells_of_type(const VtuData& d, const std::string& source, int type, int corners,
                  const char* type_name) {
  const auto n = static_cast<Eigen::Index>(d.types.size());
  if (n == 0) throw_input_error(source, "empty mesh: the file has no cells");
  Mat cells(n, corners);
  for (Eigen::Index c = 0; c < n; ++c) {
    const int64_t begin = c == 0 ? 0 : d.offsets[c - 1];
    if (d.types[c] != type || d.offsets[c] - begin != corners)
      throw_input_error(source, "cell " + std::to_string(c) + " has VTK type " +
                                    std::to_string(d.types[c]) + " with " +
                                    std::to_string(d.offsets[c] - begin) + " vertices; expected " +
                                    type_name + " (type " + std::to_string(type) + ", " +
                                    std::to_string(corners) + " vertices)");
    for (int k = 0; k < corners; ++k) cells(c, k) = static_cast<int>(d.connectivity[begin + k]);
  }
  return cells;
}

}  // namespace

TetMesh read_vtu_tet_mesh(const std::filesystem::path& path) {
  const VtuData d = read_vtu(path);
  TetMesh m;
  m.V = d.points;
  m.T = cells_of_type<MatX4i>(d, path.string(), 10, 4, "VTK_TETRA");
  const Eigen::VectorXd vol = signed_tet_volumes(m.V, m.T);
  for (Eigen::Index e = 0; e < vol.size(); ++e)
    if (!(vol[e] > 0))
      throw_input_error(path.string(), "tet " + std::to_string(e) +
                                           " is inverted or degenerate "
                                           "(signed volume " +
                                           std::to_string(vol[e]) + ")");
  m.F = boundary_faces(m.T);
  return m;
}

SurfaceMesh read_vtu_surface_mesh(const std::filesystem::path& path) {
  const VtuData d = read_vtu(path);
  SurfaceMesh m;
  m.V = d.points;
  m.F = cells_of_type<MatX3i>(d, path.string(), 5, 3, "VTK_TRIANGLE");
  return m;
}

SphereSet read_vtu_sphere_set(const std::filesystem::path& path) {
  const VtuData d = read_vtu(path);
  using MatX1i = Eigen::Matrix<int, Eigen::Dynamic, 1>;
  const MatX1i cells = cells_of_type<MatX1i>(d, path.string(), 1, 1, "VTK_VERTEX");
  SphereSet s;
  s.centers.resize(cells.rows(), 3);
  for (Eigen::Index i = 0; i < cells.rows(); ++i) s.centers.row(i) = d.points.row(cells[i]);
  const PointDataArray* radius = nullptr;
  for (const PointDataArray& a : d.point_data)
    if (a.name == "radius") radius = &a;
  if (!radius || radius->values.cols() != 1)
    throw_input_error(path.string(), "a sphere set needs a one-component PointData array 'radius'");
  s.radii.resize(cells.rows());
  for (Eigen::Index i = 0; i < cells.rows(); ++i) {
    s.radii[i] = radius->values(cells[i], 0);
    if (s.radii[i] < 0)
      throw_input_error(path.string(), "sphere " + std::to_string(i) + " has negative radius " +
                                           std::to_string(s.radii[i]));
  }
  return s;
}

}  // namespace icd
