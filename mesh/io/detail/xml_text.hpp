#pragma once
/// Internal: escaping text for XML attribute values, and the reverse.
#include <string>
#include <string_view>

namespace icd::detail {

/// Replaces & < > " ' by their entities.
std::string xml_escape(std::string_view s);
/// Replaces the five predefined entities and &#N; / &#xN; (ASCII only) by their
/// characters; false for an unknown or malformed entity.
bool xml_unescape(std::string_view s, std::string& out);

}  // namespace icd::detail
