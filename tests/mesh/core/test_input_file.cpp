#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/input_file.hpp>

namespace icd {
namespace {

namespace fs = std::filesystem;

std::string error_of(const fs::path& p, std::uint64_t limit) {
  try {
    read_input_file(p, limit, "test file");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(InputFile, ReadsARegularFileWithinItsLimit) {
  const fs::path p = fs::path(::testing::TempDir()) / "icd_input_file_ok.txt";
  std::ofstream(p) << "hello";
  EXPECT_EQ(read_input_file(p, 5, "test file"), "hello");
  EXPECT_EQ(check_input_file(p, 5, "test file"), 5u);
}

// Folders, devices and missing files are named as such; a file above its
// limit is refused by its size, without reading it.
TEST(InputFile, RefusesWhatIsNotARegularFileOrTooLarge) {
  const fs::path dir = fs::path(::testing::TempDir());
  EXPECT_NE(error_of(dir, 100).find("not a regular file (a directory)"), std::string::npos);
  EXPECT_NE(error_of("/dev/zero", 100)
                .find("/dev/zero: cannot open file: not a regular file (a "
                      "character device)"),
            std::string::npos);
  EXPECT_NE(error_of(dir / "icd_no_such_file", 100).find("no such file"), std::string::npos);
  const fs::path big = dir / "icd_input_file_big.bin";
  std::ofstream(big).close();
  fs::resize_file(big, 3 * file_limits::kMiB);  // sparse
  const std::string msg = error_of(big, 2 * file_limits::kMiB);
  EXPECT_NE(msg.find("test file of 3145728 bytes (3 MiB) is larger than the limit of 2 MiB"),
            std::string::npos)
      << msg;
  fs::remove(big);
}

TEST(InputFile, EscapesEveryByteOutsidePrintableAscii) {
  EXPECT_EQ(escape_bytes(std::string("a\0b\n\xEF\x7F~", 7)), "a\\x00b\\x0a\\xef\\x7f~");
  EXPECT_EQ(escape_bytes("abcdef", 3), "abc...");
  EXPECT_EQ(strip_utf8_bom("\xEF\xBB\xBFOFF"), "OFF");
  EXPECT_EQ(strip_utf8_bom("\xEF\xBBOFF"), "\xEF\xBBOFF");
}

}  // namespace
}  // namespace icd
