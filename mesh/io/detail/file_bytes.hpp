#pragma once
/// Internal helper: read a whole file into memory with precise errors.
#include <filesystem>
#include <string>

namespace icd::detail {

/// The bytes of a regular file. Throws InputError "<path>: cannot open ..."
/// for a missing, unreadable or non-regular file.
std::string read_file_bytes(const std::filesystem::path& path);

/// Throws the same errors as read_file_bytes when `path` is missing or not a
/// regular file, without reading it.
void check_regular_file(const std::filesystem::path& path);

}  // namespace icd::detail
