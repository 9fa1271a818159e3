#include <icd/mesh/io/atomic_write.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>

#include <icd/mesh/core/error.hpp>

namespace icd {

namespace {

std::filesystem::path part_of(const std::filesystem::path& path) {
  std::filesystem::path part = path;
  part += ".part";
  return part;
}

// Removes the .part file and throws the one error of this file.
[[noreturn]] void cannot_write(const std::filesystem::path& path,
                               const std::filesystem::path& part, const std::string& why) {
  std::error_code ignored;
  std::filesystem::remove(part, ignored);
  throw InputError(path.string() + ": cannot write file: " + why);
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::string_view contents) {
  const std::filesystem::path part = part_of(path);
  std::FILE* f = std::fopen(part.string().c_str(), "wb");
  if (!f) cannot_write(path, part, part.string() + ": " + std::strerror(errno));
  const size_t written = std::fwrite(contents.data(), 1, contents.size(), f);
  const int write_errno = errno;
  const bool flushed = std::fflush(f) == 0;
  const bool closed = std::fclose(f) == 0;
  if (written != contents.size() || !flushed || !closed)
    cannot_write(path, part,
                 std::string("write to ") + part.string() + " failed: " + std::strerror(write_errno));
  std::error_code ec;
  std::filesystem::rename(part, path, ec);
  if (ec) cannot_write(path, part, "rename from " + part.string() + " failed: " + ec.message());
}

void check_writable(const std::filesystem::path& path) {
  const std::filesystem::path part = part_of(path);
  std::FILE* f = std::fopen(part.string().c_str(), "wb");
  if (!f) cannot_write(path, part, part.string() + ": " + std::strerror(errno));
  std::fclose(f);
  std::error_code ec;
  std::filesystem::remove(part, ec);
  if (ec) cannot_write(path, part, "cannot remove " + part.string() + ": " + ec.message());
}

}  // namespace icd
