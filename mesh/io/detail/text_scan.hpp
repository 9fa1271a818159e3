#pragma once
/// Internal helpers of the mesh readers: line splitting, tokenizing and
/// strict number parsing over an in-memory buffer (no allocation per token).
#include <cstdint>
#include <string>
#include <string_view>

namespace icd::detail {

/// Splits a buffer into lines (LF, CRLF or lone CR terminated) and counts
/// 1-based line numbers.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : m_text(text) {}

  /// Stores the next line (without its terminator) in `line`; false at the end.
  bool next(std::string_view& line);
  /// 1-based number of the line last returned by next() (0 before the first).
  int64_t line_number() const { return m_line; }
  /// Bytes not yet returned by next().
  size_t bytes_left() const { return m_text.size() - m_pos; }

 private:
  std::string_view m_text;
  size_t m_pos = 0;
  int64_t m_line = 0;
};

/// Whitespace-separated tokens of one line.
class Tokens {
 public:
  explicit Tokens(std::string_view line) : m_line(line) {}
  /// Stores the next token in `token`; false when none is left.
  bool next(std::string_view& token);
  /// True when only whitespace remains.
  bool at_end();

 private:
  std::string_view m_line;
  size_t m_pos = 0;
};

/// Whitespace-separated tokens across a whole buffer, tracking line numbers
/// (for formats that are token streams: ASCII PLY, ASCII STL, VTU arrays).
class TokenStream {
 public:
  explicit TokenStream(std::string_view text, int64_t first_line = 1)
      : m_text(text), m_line(first_line) {}
  /// Stores the next token in `token`; false at the end of the buffer.
  bool next(std::string_view& token);
  /// Skips the remainder of the current line.
  void skip_line();
  /// Returns the remainder of the current line (trimmed) and moves past it.
  std::string_view rest_of_line();
  /// 1-based line of the last token returned (or of the current position).
  int64_t line_number() const { return m_line; }
  /// Bytes not yet consumed.
  size_t bytes_left() const { return m_text.size() - m_pos; }

 private:
  std::string_view m_text;
  size_t m_pos = 0;
  int64_t m_line;
};

/// Removes a trailing comment starting at `marker` and surrounding whitespace.
std::string_view strip_comment(std::string_view line, char marker);
/// Removes leading and trailing whitespace.
std::string_view trim(std::string_view s);
/// True for ' ', '\t', '\n', '\r', '\v', '\f'.
constexpr bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/// Outcome of a strict number parse.
enum class NumberStatus { ok, not_a_number, out_of_range };

/// Parses the whole token as a double (std::from_chars, optional leading '+').
/// "nan" and "inf" parse as ok: callers decide whether non-finite values are allowed.
NumberStatus parse_double(std::string_view token, double& out);
/// Parses the whole token as a decimal integer (optional leading '+').
NumberStatus parse_int64(std::string_view token, int64_t& out);

/// The token quoted for an error message: at most 40 characters, non-printable
/// bytes written as \xNN.
std::string quote(std::string_view token);

}  // namespace icd::detail
