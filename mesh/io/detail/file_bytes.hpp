#pragma once
/// Internal helper: read a whole file into memory with precise errors.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include <icd/mesh/core/input_file.hpp>

namespace icd::detail {

/// The bytes of a regular file of at most `max_bytes` bytes (icd::read_input_file;
/// `what` names the kind of file in the size message). Throws InputError
/// "<path>: cannot open ..." for a missing, unreadable or non-regular file,
/// and for a file above the limit (before reading it).
std::string read_file_bytes(const std::filesystem::path& path, std::uint64_t max_bytes,
                            std::string_view what);

/// Throws the same errors as read_file_bytes when `path` is missing, not a
/// regular file or above `max_bytes`, without reading it.
void check_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                        std::string_view what);

}  // namespace icd::detail
