#pragma once
/// Internal: appending numbers to text output, shortest form that reads back
/// to the identical double (std::to_chars).
#include <charconv>
#include <cstdint>
#include <string>

namespace icd::detail {

/// Appends the shortest decimal form of `v` that round-trips exactly.
inline void append_number(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, static_cast<size_t>(r.ptr - buf));
}

/// Appends the decimal form of an integer.
inline void append_number(std::string& out, int64_t v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, static_cast<size_t>(r.ptr - buf));
}

}  // namespace icd::detail
