// OFF reader: "[ST][C][N]OFF" header, counts "#V #F #E", #V vertex lines
// (x y z, then optional normal/colour/texture data for the N/C/ST variants),
// #F face lines "n i1 ... in [colour]". '#' starts a comment. A UTF-8
// byte-order mark is skipped; content after the last announced face is an
// error (the header's face count is wrong).
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

// The next line with content, comments removed; false at the end of the file.
bool next_content_line(detail::LineReader& lines, std::string_view& line) {
  std::string_view raw;
  while (lines.next(raw)) {
    line = detail::strip_comment(raw, '#');
    if (!line.empty()) return true;
  }
  return false;
}

// Whether `keyword` is an OFF header we read; sets `extra` when vertex lines
// may carry more than 3 numbers.
bool parse_header_keyword(std::string_view keyword, bool& extra) {
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF") return false;
  std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  extra = !prefix.empty();
  if (prefix.starts_with("ST")) prefix.remove_prefix(2);
  if (prefix.starts_with("C")) prefix.remove_prefix(1);
  if (prefix.starts_with("N")) prefix.remove_prefix(1);
  return prefix.empty();
}

int64_t parse_count(std::string_view source, int64_t line, std::string_view token,
                    std::string_view what) {
  int64_t v = 0;
  const NumberStatus s = detail::parse_int64(token, v);
  if (s != NumberStatus::ok)
    throw_input_error(
        source, line,
        "expected the number of " + std::string(what) + ", found " + detail::quote(token));
  return v;
}

}  // namespace

SurfaceMesh parse_off(std::string_view bytes, std::string_view source, ReadReport* report) {
  detail::LineReader lines(strip_utf8_bom(bytes));
  std::string_view line;
  if (!next_content_line(lines, line))
    throw_input_error(source, "truncated file: no OFF header (the file is empty)");
  detail::Tokens header(line);
  std::string_view tok;
  header.next(tok);
  bool extra = false;
  if (!parse_header_keyword(tok, extra))
    throw_input_error(source, lines.line_number(),
                      "not an OFF file: expected the header 'OFF', found " + detail::quote(tok));
  const std::string keyword(tok);
  // The counts may follow the keyword on the same line or come on the next one.
  std::string_view count_tok[3];
  int found = 0;
  while (found < 3 && header.next(count_tok[found])) ++found;
  if (found == 1 && count_tok[0] == "BINARY")
    throw_input_error(source, lines.line_number(), "binary OFF is not supported");
  detail::Tokens counts_line(line);
  if (found == 0) {
    if (!next_content_line(lines, line))
      throw_input_error(source, lines.line_number(), "truncated file: missing vertex/face counts");
    counts_line = detail::Tokens(line);
    while (found < 3 && counts_line.next(count_tok[found])) ++found;
  }
  const int64_t counts_at = lines.line_number();
  if (found < 2)
    throw_input_error(source, counts_at,
                      "expected the counts '#vertices #faces #edges', found " +
                          std::to_string(found) + " numbers");
  const int64_t nv = parse_count(source, counts_at, count_tok[0], "vertices");
  const int64_t nf = parse_count(source, counts_at, count_tok[1], "faces");
  if (found == 3) (void)parse_count(source, counts_at, count_tok[2], "edges");
  // Each vertex or face line needs at least one token and a separator: a
  // loose bound, so that precise per-line errors win for small files while a
  // count the file cannot hold fails before any allocation.
  constexpr int64_t max_count = std::numeric_limits<int32_t>::max();
  const auto left = static_cast<int64_t>(lines.bytes_left());
  detail::check_count_fits(source, counts_at, "vertices", nv, 2, left, max_count);
  detail::check_count_fits(source, counts_at, "faces", nf, 2, left - 2 * nv, max_count);

  detail::SurfaceBuilder builder(source);
  builder.reserve(nv, nf);
  for (int64_t i = 0; i < nv; ++i) {
    if (!next_content_line(lines, line))
      throw_input_error(
          source, lines.line_number(),
          "truncated file: expected vertex " + std::to_string(i) + " of " + std::to_string(nv));
    detail::Tokens t(line);
    double xyz[3];
    for (double& c : xyz) {
      if (!t.next(tok))
        throw_input_error(source, lines.line_number(),
                          "vertex " + std::to_string(i) + ": expected 3 coordinates");
      const NumberStatus s = detail::parse_double(tok, c);
      if (s != NumberStatus::ok)
        throw_input_error(source, lines.line_number(),
                          "vertex " + std::to_string(i) + ": coordinate " + detail::quote(tok) +
                              (s == NumberStatus::out_of_range ? " is out of the double range"
                                                               : " is not a number"));
    }
    if (!extra && !t.at_end()) {
      t.next(tok);
      throw_input_error(source, lines.line_number(),
                        "vertex " + std::to_string(i) + ": unexpected token " + detail::quote(tok) +
                            " after the 3 coordinates (plain OFF)");
    }
    builder.add_vertex(xyz[0], xyz[1], xyz[2], lines.line_number());
  }
  std::vector<int64_t> corners;
  for (int64_t f = 0; f < nf; ++f) {
    if (!next_content_line(lines, line))
      throw_input_error(
          source, lines.line_number(),
          "truncated file: expected face " + std::to_string(f) + " of " + std::to_string(nf));
    detail::Tokens t(line);
    t.next(tok);
    int64_t n = 0;
    if (detail::parse_int64(tok, n) != NumberStatus::ok)
      throw_input_error(
          source, lines.line_number(),
          "face " + std::to_string(f) + ": expected the vertex count, found " + detail::quote(tok));
    if (n < 3)
      throw_input_error(source, lines.line_number(),
                        "face " + std::to_string(f) + ": has " + std::to_string(n) +
                            " vertices; at least 3 are needed");
    corners.clear();
    for (int64_t k = 0; k < n; ++k) {
      if (!t.next(tok))
        throw_input_error(source, lines.line_number(),
                          "face " + std::to_string(f) + ": expected " + std::to_string(n) +
                              " vertex indices, found " + std::to_string(k));
      int64_t idx = 0;
      const NumberStatus s = detail::parse_int64(tok, idx);
      if (s == NumberStatus::not_a_number)
        throw_input_error(source, lines.line_number(),
                          "face " + std::to_string(f) + ": vertex index " + detail::quote(tok) +
                              " is not an integer");
      if (s == NumberStatus::out_of_range || idx < 0 || idx >= nv)
        throw_input_error(source, lines.line_number(),
                          "face " + std::to_string(f) + ": vertex index " + std::string(tok) +
                              " is out of range (the mesh has " + std::to_string(nv) +
                              " vertices)");
      corners.push_back(idx);
    }
    // Anything after the indices is a face colour, which we ignore.
    builder.add_polygon(corners, lines.line_number());
  }
  if (next_content_line(lines, line))
    throw_input_error(source, lines.line_number(),
                      "the header announces " + std::to_string(nv) + " vertices and " +
                          std::to_string(nf) + (nf == 1 ? " face" : " faces") +
                          ", but more data follows the last face: " + detail::quote(line) +
                          " (wrong face count in the header?)");
  return builder.finish(keyword, report);
}

}  // namespace icd
