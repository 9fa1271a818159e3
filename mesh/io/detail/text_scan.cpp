#include <icd/mesh/io/detail/text_scan.hpp>

#include <charconv>
#include <system_error>

#include <icd/mesh/core/input_file.hpp>

namespace icd::detail {

bool LineReader::next(std::string_view& line) {
  if (m_pos >= m_text.size()) return false;
  const size_t start = m_pos;
  size_t end = start;
  while (end < m_text.size() && m_text[end] != '\n' && m_text[end] != '\r') ++end;
  line = m_text.substr(start, end - start);
  m_pos = end;
  if (m_pos < m_text.size()) {
    if (m_text[m_pos] == '\r' && m_pos + 1 < m_text.size() && m_text[m_pos + 1] == '\n') ++m_pos;
    ++m_pos;
  }
  ++m_line;
  return true;
}

bool Tokens::next(std::string_view& token) {
  while (m_pos < m_line.size() && is_space(m_line[m_pos])) ++m_pos;
  if (m_pos >= m_line.size()) return false;
  const size_t start = m_pos;
  while (m_pos < m_line.size() && !is_space(m_line[m_pos])) ++m_pos;
  token = m_line.substr(start, m_pos - start);
  return true;
}

bool Tokens::at_end() {
  while (m_pos < m_line.size() && is_space(m_line[m_pos])) ++m_pos;
  return m_pos >= m_line.size();
}

bool TokenStream::next(std::string_view& token) {
  while (m_pos < m_text.size() && is_space(m_text[m_pos])) {
    if (m_text[m_pos] == '\n' ||
        (m_text[m_pos] == '\r' && (m_pos + 1 >= m_text.size() || m_text[m_pos + 1] != '\n')))
      ++m_line;
    ++m_pos;
  }
  if (m_pos >= m_text.size()) return false;
  const size_t start = m_pos;
  while (m_pos < m_text.size() && !is_space(m_text[m_pos])) ++m_pos;
  token = m_text.substr(start, m_pos - start);
  return true;
}

void TokenStream::skip_line() { (void)rest_of_line(); }

std::string_view TokenStream::rest_of_line() {
  const size_t start = m_pos;
  while (m_pos < m_text.size() && m_text[m_pos] != '\n' && m_text[m_pos] != '\r') ++m_pos;
  return trim(m_text.substr(start, m_pos - start));
}

std::string_view trim(std::string_view s) {
  size_t b = 0, e = s.size();
  while (b < e && is_space(s[b])) ++b;
  while (e > b && is_space(s[e - 1])) --e;
  return s.substr(b, e - b);
}

std::string_view strip_comment(std::string_view line, char marker) {
  const size_t p = line.find(marker);
  if (p != std::string_view::npos) line = line.substr(0, p);
  return trim(line);
}

namespace {
std::string_view drop_plus(std::string_view t) {
  if (t.size() > 1 && t[0] == '+' && t[1] != '-' && t[1] != '+') t.remove_prefix(1);
  return t;
}
}  // namespace

NumberStatus parse_double(std::string_view token, double& out) {
  token = drop_plus(token);
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, out);
  if (ec == std::errc::result_out_of_range) return NumberStatus::out_of_range;
  if (ec != std::errc() || ptr != end || token.empty()) return NumberStatus::not_a_number;
  return NumberStatus::ok;
}

NumberStatus parse_int64(std::string_view token, int64_t& out) {
  token = drop_plus(token);
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, out);
  if (ec == std::errc::result_out_of_range) return NumberStatus::out_of_range;
  if (ec != std::errc() || ptr != end || token.empty()) return NumberStatus::not_a_number;
  return NumberStatus::ok;
}

std::string quote(std::string_view token) {
  std::string q = "'";  // (appends: GCC 12 warns falsely on "'" + string + "'")
  q += escape_bytes(token, 40);
  q += '\'';
  return q;
}

}  // namespace icd::detail
