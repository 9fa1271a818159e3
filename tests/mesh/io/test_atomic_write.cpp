// write_file_atomically and check_writable (atomic_write.hpp): the file is
// there whole or not at all, and check_writable leaves nothing behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <icd/mesh/io/atomic_write.hpp>

#include "io_test_util.hpp"

namespace icd {
namespace {

using test::expect_contains_all;
using test::input_error_message;
using test::TempDir;
using test::write_bytes;

std::string contents_of(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(AtomicWrite, WritesTheWholeFileAndLeavesNoPart) {
  TempDir dir;
  write_file_atomically(dir / "a.txt", "first\n");
  write_file_atomically(dir / "a.txt", "second, longer\n");  // replaces it whole
  EXPECT_EQ(contents_of(dir / "a.txt"), "second, longer\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "a.txt.part"));
}

TEST(AtomicWrite, CheckWritableCreatesNothingAndTouchesNoFile) {
  TempDir dir;
  check_writable(dir / "new.csv");
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  write_bytes(dir / "old.csv", "kept\n");
  check_writable(dir / "old.csv");
  EXPECT_EQ(contents_of(dir / "old.csv"), "kept\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "old.csv.part"));
}

TEST(AtomicWrite, CheckWritableRefusesAMissingFolderLikeTheWrite) {
  TempDir dir;
  const std::filesystem::path path = dir / "no_such_folder/out.csv";
  const std::string checked = input_error_message([&] { check_writable(path); });
  const std::string written = input_error_message([&] { write_file_atomically(path, "x"); });
  expect_contains_all(checked, {path.string(), "cannot write file", "No such file"});
  EXPECT_EQ(checked, written);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace icd
