#pragma once
/// Writing a whole file so that no partial output that looks complete is left
/// behind on failure.
#include <filesystem>
#include <string_view>

namespace icd {

/// Writes `contents` to `<path>.part`, flushes and closes it, then renames it
/// to `path` (replacing an existing file). On any failure the `.part` file is
/// removed, `path` is left as it was, and InputError("<path>: cannot write ...")
/// is thrown. The parent folder must exist.
void write_file_atomically(const std::filesystem::path& path, std::string_view contents);

/// For a program that builds its output while it works and writes it with
/// write_file_atomically at the end: checks up front that it could, by
/// creating `<path>.part` and removing it again, so that a missing or
/// read-only folder is reported before the work (the same InputError as
/// write_file_atomically). Creates nothing that stays; `path` is not touched.
void check_writable(const std::filesystem::path& path);

}  // namespace icd
