#include <icd/mesh/io/detail/file_bytes.hpp>

namespace icd::detail {

void check_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                        std::string_view what) {
  (void)check_input_file(path, max_bytes, what);
}

std::string read_file_bytes(const std::filesystem::path& path, std::uint64_t max_bytes,
                            std::string_view what) {
  return read_input_file(path, max_bytes, what);
}

}  // namespace icd::detail
