#pragma once
/// Internal helpers that build located InputError messages:
/// "<source>: line <n>: <what>" or "<source>: <what>".
#include <cstdint>
#include <string>
#include <string_view>

namespace icd::detail {

/// Throws InputError("<source>: line <line>: <what>"); the line part is
/// omitted when line < 1.
[[noreturn]] void throw_input_error(std::string_view source, int64_t line, std::string_view what);

/// Throws InputError("<source>: <what>").
[[noreturn]] void throw_input_error(std::string_view source, std::string_view what);

/// Fails fast when `count` items of at least `min_bytes_each` bytes cannot fit
/// in `bytes_left` bytes (or when count is negative or above `max_count`), so
/// that no allocation is ever sized from an unchecked header count.
/// `what` names the items, e.g. "vertices".
void check_count_fits(std::string_view source, int64_t line, std::string_view what, int64_t count,
                      int64_t min_bytes_each, int64_t bytes_left, int64_t max_count);

}  // namespace icd::detail
