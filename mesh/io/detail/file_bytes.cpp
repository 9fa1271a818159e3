#include <icd/mesh/io/detail/file_bytes.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <system_error>

#include <icd/mesh/io/detail/input_error.hpp>

namespace icd::detail {

void check_regular_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status))
    throw_input_error(path.string(), "cannot open file: no such file");
  if (!std::filesystem::is_regular_file(status))
    throw_input_error(path.string(), "cannot open file: not a regular file");
}

std::string read_file_bytes(const std::filesystem::path& path) {
  const std::string name = path.string();
  check_regular_file(path);
  std::error_code ec;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(name.c_str(), "rb"), &std::fclose);
  if (!f) throw_input_error(name, std::string("cannot open file: ") + std::strerror(errno));
  std::string bytes;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec) bytes.reserve(static_cast<size_t>(size));
  char chunk[1 << 16];
  size_t n = 0;
  while ((n = std::fread(chunk, 1, sizeof chunk, f.get())) > 0) bytes.append(chunk, n);
  if (std::ferror(f.get())) throw_input_error(name, "read error");
  return bytes;
}

}  // namespace icd::detail
