// OBJ reader: "v x y z [w]" and "f c1 c2 c3 ..." lines, each corner written
// i, i/t, i/t/n or i//n with 1-based (or negative, relative) vertex indices.
// '#' starts a comment; other keywords (vt, vn, g, o, s, usemtl...) are ignored.
// A UTF-8 byte-order mark is skipped.
#include <map>
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

bool is_known_ignored(std::string_view keyword) {
  static constexpr std::string_view known[] = {
      "vt",    "vn",       "vp",       "g",   "o",          "s",         "usemtl", "mtllib",
      "l",     "p",        "cstype",   "deg", "curv",       "surf",      "parm",   "end",
      "bevel", "c_interp", "d_interp", "lod", "shadow_obj", "trace_obj", "maplib", "usemap"};
  for (const auto k : known)
    if (keyword == k) return true;
  return false;
}

}  // namespace

SurfaceMesh parse_obj(std::string_view bytes, std::string_view source, ReadReport* report) {
  detail::LineReader lines(strip_utf8_bom(bytes));
  detail::SurfaceBuilder builder(source);
  std::string_view raw, tok;
  std::vector<int64_t> corners;
  std::map<std::string, int64_t> unknown;  // keyword -> number of lines
  while (lines.next(raw)) {
    const std::string_view line = detail::strip_comment(raw, '#');
    if (line.empty()) continue;
    const int64_t ln = lines.line_number();
    detail::Tokens t(line);
    t.next(tok);
    if (tok == "v") {
      double xyz[3];
      for (double& c : xyz) {
        if (!t.next(tok))
          throw_input_error(
              source, ln,
              "vertex " + std::to_string(builder.num_vertices()) + ": expected 3 coordinates");
        const NumberStatus s = detail::parse_double(tok, c);
        if (s != NumberStatus::ok)
          throw_input_error(source, ln,
                            "vertex " + std::to_string(builder.num_vertices()) + ": coordinate " +
                                detail::quote(tok) +
                                (s == NumberStatus::out_of_range ? " is out of the double range"
                                                                 : " is not a number"));
      }
      // A 4th number (w) or vertex colours may follow; they are ignored.
      builder.add_vertex(xyz[0], xyz[1], xyz[2], ln);
    } else if (tok == "f") {
      corners.clear();
      const std::string face = "face " + std::to_string(builder.num_polygons());
      while (t.next(tok)) {
        const std::string_view index = tok.substr(0, tok.find('/'));
        int64_t idx = 0;
        const NumberStatus s = detail::parse_int64(index, idx);
        if (s == NumberStatus::not_a_number)
          throw_input_error(source, ln,
                            face + ": vertex index " + detail::quote(tok) + " is not an integer");
        if (s == NumberStatus::out_of_range || idx == 0)
          throw_input_error(source, ln,
                            face + ": vertex index " + detail::quote(index) +
                                " is out of range (OBJ indices start at 1, or count back from -1)");
        if (idx < 0) {
          // Relative: -1 is the last vertex read so far.
          idx += builder.num_vertices();
          if (idx < 0)
            throw_input_error(
                source, ln,
                face + ": relative vertex index " + std::string(index) + " is out of range (only " +
                    std::to_string(builder.num_vertices()) + " vertices read so far)");
        } else {
          idx -= 1;
        }
        corners.push_back(idx);
      }
      builder.add_polygon(corners, ln);
    } else if (!is_known_ignored(tok)) {
      ++unknown[std::string(tok.substr(0, 16))];
      if (unknown.size() > 8)
        throw_input_error(
            source, ln,
            "not an OBJ file: too many unknown keywords (latest " + detail::quote(tok) + ")");
    }
  }
  for (const auto& [k, n] : unknown)
    builder.note("ignored " + std::to_string(n) + " lines with unknown keyword " +
                 detail::quote(k));
  return builder.finish("OBJ", report);
}

}  // namespace icd
