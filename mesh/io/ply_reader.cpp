// PLY reader (ascii, binary_little_endian, binary_big_endian). The header
// declares elements, each with scalar or list properties; we read x, y, z of
// `vertex` and the index list of `face`, and skip everything else by size.
// A UTF-8 byte-order mark before the header is skipped; data after the last
// element is ignored with a warning (a header count is probably wrong).
#include <bit>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <icd/mesh/core/input_file.hpp>
#include <icd/mesh/io/detail/input_error.hpp>
#include <icd/mesh/io/detail/surface_builder.hpp>
#include <icd/mesh/io/detail/text_scan.hpp>
#include <icd/mesh/io/surface_reader.hpp>

namespace icd {
namespace {

using detail::NumberStatus;
using detail::throw_input_error;

enum class Format { ascii, binary_le, binary_be };
enum class Type { i8, u8, i16, u16, i32, u32, f32, f64 };

bool parse_type(std::string_view s, Type& t) {
  struct Entry {
    std::string_view name;
    Type type;
  };
  static constexpr Entry table[] = {
      {"char", Type::i8},   {"int8", Type::i8},     {"uchar", Type::u8},   {"uint8", Type::u8},
      {"short", Type::i16}, {"int16", Type::i16},   {"ushort", Type::u16}, {"uint16", Type::u16},
      {"int", Type::i32},   {"int32", Type::i32},   {"uint", Type::u32},   {"uint32", Type::u32},
      {"float", Type::f32}, {"float32", Type::f32}, {"double", Type::f64}, {"float64", Type::f64}};
  for (const auto& e : table)
    if (s == e.name) {
      t = e.type;
      return true;
    }
  return false;
}

int64_t type_size(Type t) {
  switch (t) {
    case Type::i8:
    case Type::u8:
      return 1;
    case Type::i16:
    case Type::u16:
      return 2;
    case Type::i32:
    case Type::u32:
    case Type::f32:
      return 4;
    case Type::f64:
      return 8;
  }
  return 0;
}

bool is_integer(Type t) { return t != Type::f32 && t != Type::f64; }

struct Property {
  std::string name;
  Type type = Type::f32;  // value type (list items for a list)
  bool is_list = false;
  Type count_type = Type::u8;  // list length type
};

struct Element {
  std::string name;
  int64_t count = 0;
  int64_t header_line = 0;
  std::vector<Property> properties;
};

// Reads binary scalars with bounds checks.
class BinaryCursor {
 public:
  BinaryCursor(std::string_view data, bool big_endian) : m_data(data), m_big(big_endian) {}
  bool has(int64_t n) const { return n <= static_cast<int64_t>(m_data.size() - m_pos); }
  size_t bytes_left() const { return m_data.size() - m_pos; }
  // Precondition: has(type_size(t)).
  double read(Type t) {
    unsigned char b[8];
    const auto n = static_cast<size_t>(type_size(t));
    std::memcpy(b, m_data.data() + m_pos, n);
    m_pos += n;
    if (m_big != (std::endian::native == std::endian::big))
      for (size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    switch (t) {
      case Type::i8:
        return static_cast<int8_t>(b[0]);
      case Type::u8:
        return b[0];
      case Type::i16:
        return load<int16_t>(b);
      case Type::u16:
        return load<uint16_t>(b);
      case Type::i32:
        return load<int32_t>(b);
      case Type::u32:
        return load<uint32_t>(b);
      case Type::f32:
        return load<float>(b);
      case Type::f64:
        return load<double>(b);
    }
    return 0;
  }
  void skip(int64_t n) { m_pos += static_cast<size_t>(n); }

 private:
  template <class T>
  static double load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return static_cast<double>(v);
  }
  std::string_view m_data;
  size_t m_pos = 0;
  bool m_big;
};

struct Header {
  Format format = Format::ascii;
  std::vector<Element> elements;
  size_t data_offset = 0;
  int64_t data_line = 0;  // line where ASCII data starts
};

Header parse_header(std::string_view bytes, std::string_view source) {
  Header h;
  detail::LineReader lines(bytes);
  std::string_view line, tok;
  if (!lines.next(line) || detail::trim(line) != "ply")
    throw_input_error(source, 1, "not a PLY file: the first line must be 'ply'");
  bool have_format = false;
  while (true) {
    if (!lines.next(line))
      throw_input_error(source, lines.line_number(), "truncated header: no 'end_header' line");
    const int64_t ln = lines.line_number();
    detail::Tokens t(line);
    if (!t.next(tok)) continue;
    if (tok == "comment" || tok == "obj_info") continue;
    if (tok == "end_header") break;
    if (tok == "format") {
      std::string_view f, version;
      t.next(f);
      if (!t.next(version) || version != "1.0")
        throw_input_error(source, ln, "expected 'format <type> 1.0'");
      if (f == "ascii")
        h.format = Format::ascii;
      else if (f == "binary_little_endian")
        h.format = Format::binary_le;
      else if (f == "binary_big_endian")
        h.format = Format::binary_be;
      else
        throw_input_error(source, ln, "unknown PLY format " + detail::quote(f));
      have_format = true;
    } else if (tok == "element") {
      Element e;
      std::string_view name, count;
      if (!t.next(name) || !t.next(count))
        throw_input_error(source, ln, "expected 'element <name> <count>'");
      e.name = name;
      if (detail::parse_int64(count, e.count) != NumberStatus::ok || e.count < 0)
        throw_input_error(source, ln,
                          "element '" + e.name + "': count " + detail::quote(count) +
                              " is not a non-negative integer");
      e.header_line = ln;
      h.elements.push_back(std::move(e));
    } else if (tok == "property") {
      if (h.elements.empty())
        throw_input_error(source, ln, "'property' line before any 'element' line");
      Property p;
      std::string_view type, name;
      t.next(type);
      if (type == "list") {
        std::string_view count_type, item_type;
        if (!t.next(count_type) || !t.next(item_type) || !t.next(name))
          throw_input_error(source, ln, "expected 'property list <count type> <type> <name>'");
        p.is_list = true;
        if (!parse_type(count_type, p.count_type) || !is_integer(p.count_type))
          throw_input_error(
              source, ln,
              "list count type " + detail::quote(count_type) + " is not an integer type");
        if (!parse_type(item_type, p.type))
          throw_input_error(source, ln, "unknown property type " + detail::quote(item_type));
      } else {
        if (!parse_type(type, p.type))
          throw_input_error(source, ln, "unknown property type " + detail::quote(type));
        if (!t.next(name)) throw_input_error(source, ln, "expected 'property <type> <name>'");
      }
      p.name = name;
      h.elements.back().properties.push_back(std::move(p));
    } else {
      throw_input_error(source, ln, "unknown header keyword " + detail::quote(tok));
    }
  }
  if (!have_format) throw_input_error(source, "header has no 'format' line");
  h.data_offset = bytes.size() - lines.bytes_left();
  h.data_line = lines.line_number() + 1;
  return h;
}

// Minimum bytes one row of `e` takes (binary: exact for scalars, the count for
// lists; ascii: one token and a separator, a loose bound so that precise
// per-row errors win for small files).
int64_t min_row_bytes(const Element& e, Format f) {
  if (f == Format::ascii) return e.properties.empty() ? 0 : 2;
  int64_t n = 0;
  for (const auto& p : e.properties) n += type_size(p.is_list ? p.count_type : p.type);
  return n;
}

struct Roles {
  int vertex = -1, face = -1;  // element indices
  int x = -1, y = -1, z = -1;  // property indices in the vertex element
  int indices = -1;            // property index in the face element
};

Roles find_roles(const Header& h, std::string_view source) {
  Roles r;
  for (size_t i = 0; i < h.elements.size(); ++i) {
    if (h.elements[i].name == "vertex" && r.vertex < 0) r.vertex = static_cast<int>(i);
    if (h.elements[i].name == "face" && r.face < 0) r.face = static_cast<int>(i);
  }
  if (r.vertex < 0) throw_input_error(source, "header declares no 'vertex' element");
  const Element& v = h.elements[r.vertex];
  for (size_t k = 0; k < v.properties.size(); ++k) {
    const Property& p = v.properties[k];
    int* slot = p.name == "x" ? &r.x : p.name == "y" ? &r.y : p.name == "z" ? &r.z : nullptr;
    if (!slot) continue;
    if (p.is_list)
      throw_input_error(source, v.header_line, "vertex property '" + p.name + "' is a list");
    *slot = static_cast<int>(k);
  }
  for (const auto& [slot, name] : {std::pair{r.x, "x"}, {r.y, "y"}, {r.z, "z"}})
    if (slot < 0)
      throw_input_error(source, v.header_line,
                        std::string("vertex element has no property '") + name + "'");
  if (r.face < 0) throw_input_error(source, "empty mesh: header declares no 'face' element");
  const Element& f = h.elements[r.face];
  for (size_t k = 0; k < f.properties.size(); ++k) {
    const Property& p = f.properties[k];
    if (p.name == "vertex_indices" || p.name == "vertex_index") {
      if (!p.is_list || !is_integer(p.type))
        throw_input_error(source, f.header_line,
                          "face property '" + p.name + "' must be a list of integers");
      r.indices = static_cast<int>(k);
    }
  }
  if (r.indices < 0)
    throw_input_error(source, f.header_line,
                      "face element has no list property 'vertex_indices' or 'vertex_index'");
  return r;
}

void read_binary(std::string_view data, const Header& h, const Roles& r, std::string_view source,
                 detail::SurfaceBuilder& builder) {
  BinaryCursor cur(data, h.format == Format::binary_be);
  std::vector<int64_t> corners;
  for (size_t ei = 0; ei < h.elements.size(); ++ei) {
    const Element& e = h.elements[ei];
    if (e.properties.empty()) continue;
    const bool is_vertex = static_cast<int>(ei) == r.vertex;
    const bool is_face = static_cast<int>(ei) == r.face;
    for (int64_t row = 0; row < e.count; ++row) {
      double xyz[3] = {0, 0, 0};
      for (size_t k = 0; k < e.properties.size(); ++k) {
        const Property& p = e.properties[k];
        const auto truncated = [&] {
          throw_input_error(source, "truncated data: " + e.name + " " + std::to_string(row) +
                                        " (property '" + p.name +
                                        "') ends past the end of the file");
        };
        if (!p.is_list) {
          if (!cur.has(type_size(p.type))) truncated();
          if (!is_vertex) {
            cur.skip(type_size(p.type));
            continue;
          }
          const double value = cur.read(p.type);
          const int ki = static_cast<int>(k);
          if (ki == r.x) xyz[0] = value;
          if (ki == r.y) xyz[1] = value;
          if (ki == r.z) xyz[2] = value;
          continue;
        }
        if (!cur.has(type_size(p.count_type))) truncated();
        const double n = cur.read(p.count_type);
        if (n < 0)
          throw_input_error(source, e.name + " " + std::to_string(row) + ": list '" + p.name +
                                        "' has negative length " + std::to_string(n));
        const auto len = static_cast<int64_t>(n);
        if (!cur.has(len * type_size(p.type))) truncated();
        if (!(is_face && static_cast<int>(k) == r.indices)) {
          cur.skip(len * type_size(p.type));
          continue;
        }
        corners.clear();
        for (int64_t c = 0; c < len; ++c) corners.push_back(static_cast<int64_t>(cur.read(p.type)));
        builder.add_polygon(corners, 0);
      }
      if (is_vertex) builder.add_vertex(xyz[0], xyz[1], xyz[2], 0);
    }
  }
  if (cur.bytes_left() > 0)
    builder.warn("ignored " + std::to_string(cur.bytes_left()) +
                 " bytes after the last element announced by the header");
}

void read_ascii(std::string_view data, const Header& h, const Roles& r, std::string_view source,
                detail::SurfaceBuilder& builder) {
  detail::TokenStream ts(data, h.data_line);
  std::string_view tok;
  std::vector<int64_t> corners;
  for (size_t ei = 0; ei < h.elements.size(); ++ei) {
    const Element& e = h.elements[ei];
    if (e.properties.empty()) continue;
    const bool is_vertex = static_cast<int>(ei) == r.vertex;
    const bool is_face = static_cast<int>(ei) == r.face;
    for (int64_t row = 0; row < e.count; ++row) {
      double xyz[3] = {0, 0, 0};
      int64_t row_line = 0;
      for (size_t k = 0; k < e.properties.size(); ++k) {
        const Property& p = e.properties[k];
        const auto where = [&] {
          return e.name + " " + std::to_string(row) + ": property '" + p.name + "'";
        };
        const auto next = [&] {
          if (!ts.next(tok))
            throw_input_error(source, ts.line_number(),
                              "truncated data: " + where() + " is missing");
          if (row_line == 0) row_line = ts.line_number();
        };
        const auto number = [&](Type t) {
          double v = 0;
          int64_t i = 0;
          const NumberStatus s =
              is_integer(t) ? detail::parse_int64(tok, i) : detail::parse_double(tok, v);
          if (s != NumberStatus::ok)
            throw_input_error(source, ts.line_number(),
                              where() + ": " + detail::quote(tok) + " is not " +
                                  (is_integer(t) ? "an integer" : "a number") +
                                  (s == NumberStatus::out_of_range ? " in range" : ""));
          return is_integer(t) ? static_cast<double>(i) : v;
        };
        next();
        if (!p.is_list) {
          const double value = number(p.type);
          const int ki = static_cast<int>(k);
          if (is_vertex && ki == r.x) xyz[0] = value;
          if (is_vertex && ki == r.y) xyz[1] = value;
          if (is_vertex && ki == r.z) xyz[2] = value;
          continue;
        }
        const double n = number(p.count_type);
        if (n < 0 || n > static_cast<double>(ts.bytes_left()))
          throw_input_error(source, ts.line_number(),
                            where() + ": list length " + std::string(tok) +
                                " is negative or longer than the rest of the file");
        const auto len = static_cast<int64_t>(n);
        const bool keep = is_face && static_cast<int>(k) == r.indices;
        corners.clear();
        for (int64_t c = 0; c < len; ++c) {
          next();
          const double v = number(p.type);
          if (keep) corners.push_back(static_cast<int64_t>(v));
        }
        if (keep) builder.add_polygon(corners, row_line);
      }
      if (is_vertex) builder.add_vertex(xyz[0], xyz[1], xyz[2], row_line);
    }
  }
  if (ts.next(tok))
    builder.warn("ignored data after the last element announced by the header (from line " +
                 std::to_string(ts.line_number()) + ")");
}

}  // namespace

SurfaceMesh parse_ply(std::string_view bytes_in, std::string_view source, ReadReport* report) {
  const std::string_view bytes = strip_utf8_bom(bytes_in);
  const Header h = parse_header(bytes, source);
  const Roles roles = find_roles(h, source);
  const std::string_view data = bytes.substr(h.data_offset);
  // Fail fast on counts the file cannot hold, before any allocation.
  const auto left = static_cast<int64_t>(data.size());
  int64_t left_for_rest = left;
  for (const Element& e : h.elements) {
    const int64_t row = min_row_bytes(e, h.format);
    const bool is_mesh = &e == &h.elements[roles.vertex] || &e == &h.elements[roles.face];
    const int64_t max_count =
        is_mesh ? std::numeric_limits<int32_t>::max() : std::numeric_limits<int64_t>::max() / 64;
    detail::check_count_fits(source, e.header_line, "'" + e.name + "' elements", e.count, row,
                             left_for_rest, max_count);
    left_for_rest -= e.count * row;
  }
  detail::SurfaceBuilder builder(source);
  builder.reserve(h.elements[roles.vertex].count, h.elements[roles.face].count);
  std::string format;
  if (h.format == Format::ascii) {
    read_ascii(data, h, roles, source, builder);
    format = "PLY ascii";
  } else {
    read_binary(data, h, roles, source, builder);
    format = h.format == Format::binary_le ? "PLY binary_little_endian" : "PLY binary_big_endian";
  }
  return builder.finish(format, report);
}

}  // namespace icd
