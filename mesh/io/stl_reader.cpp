// STL reader. Binary: 80-byte header, uint32 triangle count, then per
// triangle 12 little-endian floats (normal, 3 corners) and a uint16. ASCII:
// "solid name / facet normal ... / outer loop / vertex x y z (x3) / endloop /
// endfacet / endsolid", optionally after a UTF-8 byte-order mark. A file is
// binary exactly when its size is 84 + 50 * count; otherwise it must be ASCII.
// Corners with identical coordinates are welded.
#include <bit>
#include <cstring>
#include <string>
#include <unordered_map>
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

struct Key {
  double x, y, z;
  bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
};

struct KeyHash {
  size_t operator()(const Key& k) const {
    // +0.0 and -0.0 compare equal, so they must hash equally.
    const auto bits = [](double v) { return std::bit_cast<uint64_t>(v == 0.0 ? 0.0 : v); };
    uint64_t h = bits(k.x) * 0x9E3779B97F4A7C15ull;
    h ^= bits(k.y) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= bits(k.z) + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
    return static_cast<size_t>(h ^ (h >> 31));
  }
};

// Maps corner coordinates to welded vertex indices.
class Welder {
 public:
  explicit Welder(detail::SurfaceBuilder& b) : m_builder(b) {}
  int64_t index(double x, double y, double z, int64_t line) {
    const auto [it, inserted] = m_map.try_emplace(Key{x, y, z}, m_builder.num_vertices());
    if (inserted) {
      m_builder.add_vertex(x, y, z, line);  // throws on NaN/Inf before any use
    } else {
      ++m_welded;
    }
    return it->second;
  }
  void reserve(size_t n) { m_map.reserve(n); }
  int64_t welded() const { return m_welded; }

 private:
  detail::SurfaceBuilder& m_builder;
  std::unordered_map<Key, int64_t, KeyHash> m_map;
  int64_t m_welded = 0;
};

float load_le_float(const char* p) {
  unsigned char b[4];
  std::memcpy(b, p, 4);
  if constexpr (std::endian::native == std::endian::big) {
    std::swap(b[0], b[3]);
    std::swap(b[1], b[2]);
  }
  float f;
  std::memcpy(&f, b, 4);
  return f;
}

uint32_t load_le_u32(const char* p) {
  const auto* b = reinterpret_cast<const unsigned char*>(p);
  return static_cast<uint32_t>(b[0]) | static_cast<uint32_t>(b[1]) << 8 |
         static_cast<uint32_t>(b[2]) << 16 | static_cast<uint32_t>(b[3]) << 24;
}

void read_binary(std::string_view bytes, std::string_view source, detail::SurfaceBuilder& builder,
                 Welder& welder) {
  const int64_t n = load_le_u32(bytes.data() + 80);
  const auto size = static_cast<int64_t>(bytes.size());
  if (84 + 50 * n > size)
    throw_input_error(source, "truncated binary STL: header announces " + std::to_string(n) +
                                  " triangles (84 + 50 * " + std::to_string(n) + " = " +
                                  std::to_string(84 + 50 * n) + " bytes) but the file has " +
                                  std::to_string(size) + " bytes");
  if (84 + 50 * n < size) {
    const int64_t extra = size - 84 - 50 * n;
    throw_input_error(
        source,
        "binary STL: header announces " + std::to_string(n) + " triangles (84 + 50 * " +
            std::to_string(n) + " = " + std::to_string(84 + 50 * n) + " bytes) but the file has " +
            std::to_string(size) + " bytes" +
            (extra % 50 == 0 ? " (" + std::to_string(n + extra / 50) + " triangles' worth)" : "") +
            ": wrong triangle count in the header, or data after the last triangle");
  }
  // Room for every corner distinct (the worst case): no rehash while welding.
  welder.reserve(static_cast<size_t>(3 * n));
  builder.reserve(n / 2 + 3, n);
  int64_t corners[3];
  for (int64_t t = 0; t < n; ++t) {
    const char* p = bytes.data() + 84 + 50 * t + 12;  // skip the normal
    for (int c = 0; c < 3; ++c)
      corners[c] = welder.index(load_le_float(p + 12 * c), load_le_float(p + 12 * c + 4),
                                load_le_float(p + 12 * c + 8), 0);
    builder.add_polygon(corners, 0);
  }
}

void read_ascii(std::string_view bytes, std::string_view source, detail::SurfaceBuilder& builder,
                Welder& welder) {
  detail::TokenStream ts(bytes);
  std::string_view tok;
  const auto expect = [&](std::string_view word, std::string_view context) {
    if (!ts.next(tok))
      throw_input_error(
          source, ts.line_number(),
          "truncated file: expected '" + std::string(word) + "' " + std::string(context));
    if (tok != word)
      throw_input_error(source, ts.line_number(),
                        "expected '" + std::string(word) + "' " + std::string(context) +
                            ", found " + detail::quote(tok));
  };
  const auto number = [&](std::string_view what) {
    if (!ts.next(tok))
      throw_input_error(source, ts.line_number(), "truncated file: expected " + std::string(what));
    double v = 0;
    const NumberStatus s = detail::parse_double(tok, v);
    if (s != NumberStatus::ok)
      throw_input_error(source, ts.line_number(),
                        std::string(what) + ": " + detail::quote(tok) +
                            (s == NumberStatus::out_of_range ? " is out of the double range"
                                                             : " is not a number"));
    return v;
  };
  std::vector<int64_t> corners;
  expect("solid", "at the start of an ASCII STL file");
  ts.skip_line();  // the solid's name
  while (true) {
    if (!ts.next(tok))
      throw_input_error(source, ts.line_number(), "truncated file: missing 'endsolid'");
    if (tok == "endsolid") {
      ts.skip_line();
      if (!ts.next(tok)) break;  // end of file
      if (tok != "solid")
        throw_input_error(source, ts.line_number(),
                          "expected 'solid' or the end of the file after 'endsolid', found " +
                              detail::quote(tok));
      ts.skip_line();
      continue;
    }
    const std::string facet = "facet " + std::to_string(builder.num_polygons());
    if (tok != "facet")
      throw_input_error(source, ts.line_number(),
                        "expected 'facet' or 'endsolid', found " + detail::quote(tok));
    const int64_t facet_line = ts.line_number();
    expect("normal", "after 'facet'");
    for (int c = 0; c < 3; ++c) (void)number(facet + ": normal component");
    expect("outer", "in " + facet);
    expect("loop", "in " + facet);
    corners.clear();
    while (true) {
      if (!ts.next(tok))
        throw_input_error(source, ts.line_number(), "truncated file: " + facet + " is not closed");
      if (tok == "endloop") break;
      if (tok != "vertex")
        throw_input_error(source, ts.line_number(),
                          facet + ": expected 'vertex' or 'endloop', found " + detail::quote(tok));
      const int64_t ln = ts.line_number();
      const double x = number(facet + ": vertex coordinate");
      const double y = number(facet + ": vertex coordinate");
      const double z = number(facet + ": vertex coordinate");
      corners.push_back(welder.index(x, y, z, ln));
    }
    expect("endfacet", "after 'endloop' in " + facet);
    builder.add_polygon(corners, facet_line);
  }
}

}  // namespace

SurfaceMesh parse_stl(std::string_view bytes, std::string_view source, ReadReport* report) {
  detail::SurfaceBuilder builder(source);
  Welder welder(builder);
  const bool sized_as_binary =
      bytes.size() >= 84 && 84 + 50 * static_cast<int64_t>(load_le_u32(bytes.data() + 80)) ==
                                static_cast<int64_t>(bytes.size());
  const std::string_view text = strip_utf8_bom(bytes);
  const bool starts_solid = detail::trim(text.substr(0, 80)).starts_with("solid");
  std::string format;
  if (!sized_as_binary && starts_solid) {
    read_ascii(text, source, builder, welder);
    format = "STL ascii";
  } else if (bytes.size() >= 84) {
    read_binary(bytes, source, builder, welder);
    format = "STL binary";
  } else {
    throw_input_error(source, "truncated file: " + std::to_string(bytes.size()) +
                                  " bytes is too short for a binary STL (84 bytes minimum) and "
                                  "it is not an ASCII STL (no 'solid' keyword)");
  }
  builder.add_welded(welder.welded());
  if (welder.welded() > 0)
    builder.note("welded " + std::to_string(welder.welded()) +
                 " triangle corners onto identical vertices");
  return builder.finish(format, report);
}

}  // namespace icd
