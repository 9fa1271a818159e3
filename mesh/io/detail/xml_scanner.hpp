#pragma once
/// Internal: a minimal, non-validating XML tag scanner over an in-memory
/// buffer, enough for the VTK XML files we write. Errors are InputErrors
/// located by line.
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace icd::detail {

/// One XML tag: <name a="v" ...>, </name> or <name .../>, attribute values
/// unescaped.
struct Tag {
  std::string_view name;
  bool closing = false;
  bool self_closing = false;
  std::vector<std::pair<std::string, std::string>> attributes;
  size_t begin = 0;  ///< offset of '<'
  size_t end = 0;    ///< offset after '>'

  /// The value of attribute `key`, or nullptr.
  const std::string* find(std::string_view key) const;
};

/// Walks the tags of `text` in order; `source` names it in error messages.
class XmlScanner {
 public:
  XmlScanner(std::string_view text, std::string_view source) : m_text(text), m_source(source) {}

  /// The next element tag at or after the current position, skipping
  /// declarations, comments and text; false at the end of the text.
  /// Throws InputError on a malformed or unterminated tag.
  bool next(Tag& tag);
  /// 1-based line of byte `offset`.
  int64_t line_at(size_t offset) const;
  /// Throws InputError("<source>: line <line_at(offset)>: <what>").
  [[noreturn]] void fail(size_t offset, const std::string& what) const;
  /// Moves the scan position (e.g. past element content read by the caller).
  void seek(size_t pos) { m_pos = pos; }
  /// The whole buffer.
  std::string_view text() const { return m_text; }

 private:
  void parse_tag(size_t lt, Tag& tag) const;

  std::string_view m_text;
  std::string_view m_source;
  size_t m_pos = 0;
};

}  // namespace icd::detail
