#include "experiments/runner/json.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/input_file.hpp>

namespace icd::runner {

const char* Json::type_name() const {
  static constexpr const char* names[] = {"null", "bool", "number", "string", "array", "object"};
  return names[m_value.index()];
}

namespace {

class Parser {
 public:
  Parser(std::string_view text, const std::string& source)
      : m_text(strip_utf8_bom(text)), m_source(source) {}

  Json parse_document() {
    skip_ws();
    Json v = parse_value(0);
    skip_ws();
    if (m_pos != m_text.size()) fail("unexpected characters after the JSON value");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    int line = 1, col = 1;
    for (size_t i = 0; i < m_pos && i < m_text.size(); ++i) {
      if (m_text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw InputError(m_source + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " +
                     what);
  }

  void skip_ws() {
    while (m_pos < m_text.size() && (m_text[m_pos] == ' ' || m_text[m_pos] == '\t' ||
                                     m_text[m_pos] == '\n' || m_text[m_pos] == '\r'))
      ++m_pos;
  }

  bool consume(std::string_view word) {
    if (m_text.substr(m_pos, word.size()) == word) {
      m_pos += word.size();
      return true;
    }
    return false;
  }

  Json parse_value(int depth) {
    if (depth > 64) fail("nesting deeper than 64 levels");
    if (++m_values > kMaxValues)
      fail("more than " + std::to_string(kMaxValues) + " values (not a scene file?)");
    if (m_pos >= m_text.size()) fail("unexpected end of input, expected a value");
    const char c = m_text[m_pos];
    if (c == '{') return parse_object(depth);
    if (c == '[') return parse_array(depth);
    if (c == '"') return Json(parse_string());
    if (consume("true")) return Json(true);
    if (consume("false")) return Json(false);
    if (consume("null")) return Json();
    if (c == '-' || (c >= '0' && c <= '9')) return Json(parse_number());
    fail("unexpected character '" + escape_bytes(std::string_view(&c, 1)) + "', expected a value");
  }

  Json parse_object(int depth) {
    ++m_pos;  // '{'
    Json::Object obj;
    skip_ws();
    if (m_pos < m_text.size() && m_text[m_pos] == '}') {
      ++m_pos;
      return Json(std::move(obj));
    }
    for (;;) {
      skip_ws();
      if (m_pos >= m_text.size() || m_text[m_pos] != '"') fail("expected a string key");
      const size_t key_pos = m_pos;
      std::string key = parse_string();
      skip_ws();
      if (m_pos >= m_text.size() || m_text[m_pos] != ':') fail("expected ':' after key");
      ++m_pos;
      skip_ws();
      Json v = parse_value(depth + 1);
      if (obj.count(key)) {
        m_pos = key_pos;
        fail("duplicate key \"" + escape_bytes(key) + "\"");
      }
      obj.emplace(std::move(key), std::move(v));
      skip_ws();
      if (m_pos < m_text.size() && m_text[m_pos] == ',') {
        ++m_pos;
        continue;
      }
      if (m_pos < m_text.size() && m_text[m_pos] == '}') {
        ++m_pos;
        return Json(std::move(obj));
      }
      fail("expected ',' or '}' in object");
    }
  }

  Json parse_array(int depth) {
    ++m_pos;  // '['
    Json::Array arr;
    skip_ws();
    if (m_pos < m_text.size() && m_text[m_pos] == ']') {
      ++m_pos;
      return Json(std::move(arr));
    }
    for (;;) {
      skip_ws();
      arr.push_back(parse_value(depth + 1));
      skip_ws();
      if (m_pos < m_text.size() && m_text[m_pos] == ',') {
        ++m_pos;
        continue;
      }
      if (m_pos < m_text.size() && m_text[m_pos] == ']') {
        ++m_pos;
        return Json(std::move(arr));
      }
      fail("expected ',' or ']' in array");
    }
  }

  std::string parse_string() {
    ++m_pos;  // opening quote
    std::string out;
    while (m_pos < m_text.size()) {
      const char c = m_text[m_pos++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) {
        --m_pos;
        fail("control character " + escape_bytes(std::string_view(&c, 1)) + " in string");
      }
      if (static_cast<unsigned char>(c) >= 0x80) {  // RFC 8259: strings are UTF-8
        --m_pos;
        const size_t n = utf8_sequence_length(m_text.substr(m_pos));
        if (n == 0)
          fail("invalid UTF-8 byte " + escape_bytes(m_text.substr(m_pos, 1)) + " in string");
        out.append(m_text.substr(m_pos, n));
        m_pos += n;
        continue;
      }
      if (c != '\\') {
        out.push_back(c);
        continue;
      }
      if (m_pos >= m_text.size()) break;
      const char e = m_text[m_pos++];
      switch (e) {
        case '"':
          out.push_back('"');
          break;
        case '\\':
          out.push_back('\\');
          break;
        case '/':
          out.push_back('/');
          break;
        case 'b':
          out.push_back('\b');
          break;
        case 'f':
          out.push_back('\f');
          break;
        case 'n':
          out.push_back('\n');
          break;
        case 'r':
          out.push_back('\r');
          break;
        case 't':
          out.push_back('\t');
          break;
        case 'u': {
          if (m_pos + 4 > m_text.size()) fail("truncated \\u escape");
          unsigned code = 0;
          for (int k = 0; k < 4; ++k) {
            const char h = m_text[m_pos++];
            code <<= 4;
            if (h >= '0' && h <= '9')
              code |= h - '0';
            else if (h >= 'a' && h <= 'f')
              code |= h - 'a' + 10;
            else if (h >= 'A' && h <= 'F')
              code |= h - 'A' + 10;
            else
              fail("bad hex digit in \\u escape");
          }
          if (code >= 0xD800 && code <= 0xDFFF) fail("surrogate \\u escapes are not supported");
          // UTF-8 encode.
          if (code < 0x80) {
            out.push_back(static_cast<char>(code));
          } else if (code < 0x800) {
            out.push_back(static_cast<char>(0xC0 | (code >> 6)));
            out.push_back(static_cast<char>(0x80 | (code & 0x3F)));
          } else {
            out.push_back(static_cast<char>(0xE0 | (code >> 12)));
            out.push_back(static_cast<char>(0x80 | ((code >> 6) & 0x3F)));
            out.push_back(static_cast<char>(0x80 | (code & 0x3F)));
          }
          break;
        }
        default:
          --m_pos;
          fail(std::string("bad escape '\\") + e + "'");
      }
    }
    fail("unterminated string");
  }

  double parse_number() {
    // Validate the JSON number grammar, then convert with from_chars.
    const size_t start = m_pos;
    auto digits = [&] {
      const size_t s = m_pos;
      while (m_pos < m_text.size() && std::isdigit(static_cast<unsigned char>(m_text[m_pos])))
        ++m_pos;
      return m_pos - s;
    };
    if (m_text[m_pos] == '-') ++m_pos;
    if (m_pos < m_text.size() && m_text[m_pos] == '0') {
      ++m_pos;
    } else if (digits() == 0) {
      fail("malformed number");
    }
    if (m_pos < m_text.size() && m_text[m_pos] == '.') {
      ++m_pos;
      if (digits() == 0) fail("malformed number: digits expected after '.'");
    }
    if (m_pos < m_text.size() && (m_text[m_pos] == 'e' || m_text[m_pos] == 'E')) {
      ++m_pos;
      if (m_pos < m_text.size() && (m_text[m_pos] == '+' || m_text[m_pos] == '-')) ++m_pos;
      if (digits() == 0) fail("malformed number: digits expected in exponent");
    }
    double v = 0.0;
    const std::string_view token = m_text.substr(start, m_pos - start);
    const auto res = std::from_chars(token.data(), token.data() + token.size(), v);
    if (res.ec == std::errc::result_out_of_range) return out_of_range_value(token);
    if (res.ec != std::errc() || !std::isfinite(v)) {
      m_pos = start;
      fail("malformed number");
    }
    return v;
  }

  // A valid number token beyond the double range: +-infinity when it
  // overflows, +-0 when it underflows (decided by its decimal exponent), so
  // that the reader of the field can name it ("young: must be finite").
  static double out_of_range_value(std::string_view token) {
    const bool negative = token.starts_with('-');
    const size_t e = token.find_first_of("eE");
    const std::string_view mantissa =
        token.substr(negative ? 1 : 0, e == token.npos ? token.npos : e - (negative ? 1 : 0));
    // Decimal exponent of the first non-zero digit of the mantissa.
    const size_t dot = mantissa.find('.');
    const size_t int_digits = dot == mantissa.npos ? mantissa.size() : dot;
    const size_t first = mantissa.find_first_not_of("0.");
    int64_t magnitude = first == mantissa.npos ? 0
                        : first < int_digits   ? static_cast<int64_t>(int_digits - first)
                                               : -static_cast<int64_t>(first - int_digits - 1);
    if (e != token.npos) {
      int64_t exponent = 0;
      size_t k = e + 1;
      const bool exp_negative = k < token.size() && token[k] == '-';
      if (k < token.size() && (token[k] == '-' || token[k] == '+')) ++k;
      for (; k < token.size(); ++k)
        exponent = std::min<int64_t>(exponent * 10 + (token[k] - '0'), int64_t{1} << 40);
      magnitude += exp_negative ? -exponent : exponent;
    }
    const double big = std::numeric_limits<double>::infinity();
    return magnitude > 0 ? (negative ? -big : big) : (negative ? -0.0 : 0.0);
  }

  // Length of the UTF-8 sequence at the start of `s` (first byte >= 0x80),
  // or 0 if it is not a valid, shortest-form encoding of a scalar value.
  static size_t utf8_sequence_length(std::string_view s) {
    const auto b = [&](size_t i) { return static_cast<unsigned char>(s[i]); };
    const unsigned char c = b(0);
    const size_t n = c >= 0xC2 && c <= 0xDF   ? 2
                     : c >= 0xE0 && c <= 0xEF ? 3
                     : c >= 0xF0 && c <= 0xF4 ? 4
                                              : 0;
    if (n == 0 || s.size() < n) return 0;
    for (size_t i = 1; i < n; ++i)
      if ((b(i) & 0xC0) != 0x80) return 0;
    if (c == 0xE0 && b(1) < 0xA0) return 0;   // overlong
    if (c == 0xED && b(1) >= 0xA0) return 0;  // surrogate
    if (c == 0xF0 && b(1) < 0x90) return 0;   // overlong
    if (c == 0xF4 && b(1) >= 0x90) return 0;  // above U+10FFFF
    return n;
  }

  static constexpr int64_t kMaxValues = int64_t{1} << 20;

  std::string_view m_text;
  const std::string& m_source;
  size_t m_pos = 0;
  int64_t m_values = 0;
};

}  // namespace

Json parse_json(std::string_view text, const std::string& source) {
  return Parser(text, source).parse_document();
}

Json read_json_file(const std::string& path) {
  return parse_json(read_input_file(path, file_limits::kScene, "scene file"), path);
}

}  // namespace icd::runner
