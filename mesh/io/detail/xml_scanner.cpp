#include <icd/mesh/io/detail/xml_scanner.hpp>

#include <algorithm>

#include <icd/mesh/io/detail/input_error.hpp>
#include <icd/mesh/io/detail/text_scan.hpp>
#include <icd/mesh/io/detail/xml_text.hpp>

namespace icd::detail {

const std::string* Tag::find(std::string_view key) const {
  for (const auto& [k, v] : attributes)
    if (k == key) return &v;
  return nullptr;
}

int64_t XmlScanner::line_at(size_t offset) const {
  const auto end = m_text.begin() + static_cast<std::ptrdiff_t>(std::min(offset, m_text.size()));
  return 1 + std::count(m_text.begin(), end, '\n');
}

void XmlScanner::fail(size_t offset, const std::string& what) const {
  throw_input_error(m_source, line_at(offset), what);
}

bool XmlScanner::next(Tag& tag) {
  while (true) {
    const size_t lt = m_text.find('<', m_pos);
    if (lt == std::string_view::npos) return false;
    if (m_text.compare(lt, 4, "<!--") == 0) {
      const size_t e = m_text.find("-->", lt + 4);
      if (e == std::string_view::npos) fail(lt, "unterminated XML comment");
      m_pos = e + 3;
      continue;
    }
    if (m_text.compare(lt, 2, "<?") == 0 || m_text.compare(lt, 2, "<!") == 0) {
      const size_t e = m_text.find('>', lt);
      if (e == std::string_view::npos) fail(lt, "unterminated XML declaration");
      m_pos = e + 1;
      continue;
    }
    parse_tag(lt, tag);
    m_pos = tag.end;
    return true;
  }
}

void XmlScanner::parse_tag(size_t lt, Tag& tag) const {
  tag = Tag{};
  tag.begin = lt;
  size_t p = lt + 1;
  const auto at_end = [&] { return p >= m_text.size(); };
  if (!at_end() && m_text[p] == '/') {
    tag.closing = true;
    ++p;
  }
  const size_t name_start = p;
  while (!at_end() && !is_space(m_text[p]) && m_text[p] != '>' && m_text[p] != '/') ++p;
  tag.name = m_text.substr(name_start, p - name_start);
  if (tag.name.empty()) fail(lt, "malformed XML tag");
  while (true) {
    while (!at_end() && is_space(m_text[p])) ++p;
    if (at_end()) fail(lt, "unterminated XML tag <" + std::string(tag.name) + ">");
    if (m_text[p] == '>') {
      tag.end = p + 1;
      return;
    }
    if (m_text[p] == '/') {
      if (p + 1 >= m_text.size() || m_text[p + 1] != '>')
        fail(p, "malformed XML tag <" + std::string(tag.name) + ">");
      tag.self_closing = true;
      tag.end = p + 2;
      return;
    }
    const size_t key_start = p;
    while (!at_end() && m_text[p] != '=' && !is_space(m_text[p]) && m_text[p] != '>') ++p;
    const std::string key(m_text.substr(key_start, p - key_start));
    while (!at_end() && is_space(m_text[p])) ++p;
    if (at_end() || m_text[p] != '=')
      fail(p, "attribute '" + key + "' of <" + std::string(tag.name) + "> has no value");
    ++p;
    while (!at_end() && is_space(m_text[p])) ++p;
    if (at_end() || (m_text[p] != '"' && m_text[p] != '\''))
      fail(p, "attribute '" + key + "' value is not quoted");
    const char q = m_text[p++];
    const size_t close = m_text.find(q, p);
    if (close == std::string_view::npos) fail(p, "unterminated attribute '" + key + "'");
    std::string value;
    if (!xml_unescape(m_text.substr(p, close - p), value))
      fail(p, "attribute '" + key + "' has a malformed XML entity");
    tag.attributes.emplace_back(key, std::move(value));
    p = close + 1;
  }
}

}  // namespace icd::detail
