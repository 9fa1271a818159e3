#pragma once
/// A small, strict JSON reader for scene files (RFC 8259 minus surrogate
/// pairs in \u escapes). Errors name the source, line and column, and show
/// raw bytes of the input as \xNN escapes.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace icd::runner {

/// One JSON value. Objects keep their keys sorted (std::map); duplicate keys
/// are rejected at parse time.
class Json {
 public:
  using Array = std::vector<Json>;
  using Object = std::map<std::string, Json, std::less<>>;

  Json() = default;  ///< null
  explicit Json(bool b) : m_value(b) {}
  explicit Json(double d) : m_value(d) {}
  explicit Json(std::string s) : m_value(std::move(s)) {}
  explicit Json(Array a) : m_value(std::make_shared<Array>(std::move(a))) {}
  explicit Json(Object o) : m_value(std::make_shared<Object>(std::move(o))) {}

  bool is_null() const { return m_value.index() == 0; }
  bool is_bool() const { return m_value.index() == 1; }
  bool is_number() const { return m_value.index() == 2; }
  bool is_string() const { return m_value.index() == 3; }
  bool is_array() const { return m_value.index() == 4; }
  bool is_object() const { return m_value.index() == 5; }

  bool as_bool() const { return std::get<1>(m_value); }
  double as_number() const { return std::get<2>(m_value); }
  const std::string& as_string() const { return std::get<3>(m_value); }
  const Array& as_array() const { return *std::get<4>(m_value); }
  const Object& as_object() const { return *std::get<5>(m_value); }

  /// Name of the JSON type ("null", "bool", "number", "string", "array", "object").
  const char* type_name() const;

 private:
  std::variant<std::monostate, bool, double, std::string, std::shared_ptr<Array>,
               std::shared_ptr<Object>>
      m_value;
};

/// Parses `text` (a leading UTF-8 byte-order mark is skipped). Throws
/// icd::InputError "<source>:<line>:<col>: <what>" on malformed input,
/// invalid UTF-8 in a string, nesting deeper than 64, more than 2^20 values
/// and duplicate object keys. A number beyond the double range is kept as
/// +-infinity (+-0 when it underflows), for the reader of the field to refuse
/// with the field's name.
Json parse_json(std::string_view text, const std::string& source);

/// Reads and parses a file; InputError names the file when it is missing,
/// not a regular file (a folder, /dev/zero) or larger than
/// icd::file_limits::kScene (checked before reading).
Json read_json_file(const std::string& path);

}  // namespace icd::runner
