#include <icd/mesh/io/atomic_write.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>

#include <icd/mesh/core/error.hpp>

namespace icd {

void write_file_atomically(const std::filesystem::path& path, std::string_view contents) {
  std::filesystem::path part = path;
  part += ".part";
  const auto fail = [&](const std::string& why) {
    std::error_code ignored;
    std::filesystem::remove(part, ignored);
    throw InputError(path.string() + ": cannot write file: " + why);
  };
  std::FILE* f = std::fopen(part.string().c_str(), "wb");
  if (!f) fail(part.string() + ": " + std::strerror(errno));
  const size_t written = std::fwrite(contents.data(), 1, contents.size(), f);
  const int write_errno = errno;
  const bool flushed = std::fflush(f) == 0;
  const bool closed = std::fclose(f) == 0;
  if (written != contents.size() || !flushed || !closed)
    fail(std::string("write to ") + part.string() + " failed: " + std::strerror(write_errno));
  std::error_code ec;
  std::filesystem::rename(part, path, ec);
  if (ec) fail("rename from " + part.string() + " failed: " + ec.message());
}

}  // namespace icd
