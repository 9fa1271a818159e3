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

}  // namespace icd
