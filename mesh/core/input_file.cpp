#include <icd/mesh/core/input_file.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <system_error>

#include <icd/mesh/core/error.hpp>

namespace icd {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw InputError(escape_bytes(path.string(), 4096) + ": " + what);
}

std::string kind_of(std::filesystem::file_type t) {
  using std::filesystem::file_type;
  switch (t) {
    case file_type::directory:
      return "a directory";
    case file_type::character:
      return "a character device";
    case file_type::block:
      return "a block device";
    case file_type::fifo:
      return "a FIFO";
    case file_type::socket:
      return "a socket";
    default:
      return "not a plain file";
  }
}

std::string mib(std::uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g MiB", static_cast<double>(bytes) / file_limits::kMiB);
  return buf;
}

}  // namespace

std::uint64_t check_input_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                               std::string_view what) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) fail(path, "cannot open file: no such file");
  if (!std::filesystem::is_regular_file(status))
    fail(path, "cannot open file: not a regular file (" + kind_of(status.type()) + ")");
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot open file: " + ec.message());
  if (size > max_bytes)
    fail(path, std::string(what) + " of " + std::to_string(size) + " bytes (" + mib(size) +
                   ") is larger than the limit of " + mib(max_bytes));
  return size;
}

std::string read_input_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                            std::string_view what) {
  const std::uint64_t size = check_input_file(path, max_bytes, what);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) fail(path, std::string("cannot open file: ") + std::strerror(errno));
  std::string bytes;
  bytes.reserve(static_cast<std::size_t>(size));
  char chunk[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(chunk, 1, sizeof chunk, f.get())) > 0) {
    if (bytes.size() + n > max_bytes)
      fail(path,
           std::string(what) + " grew past the limit of " + mib(max_bytes) + " while it was read");
    bytes.append(chunk, n);
  }
  if (std::ferror(f.get())) fail(path, "read error");
  return bytes;
}

std::string escape_bytes(std::string_view bytes, std::size_t max_chars) {
  static constexpr char hex[] = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < bytes.size() && i < max_chars; ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  if (bytes.size() > max_chars) out += "...";
  return out;
}

}  // namespace icd
