// Issue 9, "memory and time limits": a reader never allocates from an
// unchecked header count. Each case is a tiny file whose header claims about
// 10^12 elements; the oracle is the documented contract (InputError naming
// the source). Under ICD_SANITIZE=ON an attempt to allocate from the count
// would additionally abort (AddressSanitizer refuses allocations this large).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include <icd/collision/sph_io.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/vtu_reader.hpp>
#include "tests/fuzz/bundle_fixture.hpp"

namespace icd {
namespace {

template <class F>
void expect_input_error_naming(F&& f, const std::string& source) {
  try {
    f();
    ADD_FAILURE() << source << ": accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(source), std::string::npos) << e.what();
  }
}

TEST(HeaderCounts, OffClaimingTeraVerticesFailsFast) {
  expect_input_error_naming([] { parse_off("OFF\n1000000000000 1 0\n0 0 0\n", "huge.off"); },
                            "huge.off");
  expect_input_error_naming([] { parse_off("OFF\n3 1000000000000 0\n0 0 0\n", "hugef.off"); },
                            "hugef.off");
}

TEST(HeaderCounts, PlyClaimingTeraVerticesFailsFast) {
  const std::string h =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
      "property float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  expect_input_error_naming([&] { parse_ply(h + std::string(20, '\0'), "huge.ply"); }, "huge.ply");
}

TEST(HeaderCounts, BinaryStlClaimingFourBillionTrianglesFailsFast) {
  std::string s(80, ' ');  // a header not starting with "solid"
  const uint32_t n = 0xffffffffu;
  s.append(reinterpret_cast<const char*>(&n), 4);
  s.append(20, '\0');
  expect_input_error_naming([&] { parse_stl(s, "huge.stl"); }, "huge.stl");
}

TEST(HeaderCounts, VtuClaimingTeraPointsFailsFast) {
  const std::string s =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\">"
      "<UnstructuredGrid><Piece NumberOfPoints=\"1000000000000\" NumberOfCells=\"1000000000000\">"
      "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0"
      "</DataArray></Points></Piece></UnstructuredGrid></VTKFile>\n";
  expect_input_error_naming([&] { parse_vtu(s, "huge.vtu"); }, "huge.vtu");
}

TEST(HeaderCounts, SphClaimingAHugeTreeFailsFast) {
  for (const char* header :
       {"16 64\n0 0 0 1 0\n", "1000000 2\n0 0 0 1 0\n", "12 12\n0 0 0 1 0\n"}) {
    std::istringstream in(header);
    expect_input_error_naming([&] { collision::read_sph(in, "huge.sph"); }, "huge.sph");
  }
}

TEST(HeaderCounts, BundleSectionClaimingTeraElementsFailsFast) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / "icd_reliability_bundle_counts";
  fs::remove_all(dir);
  fuzz::write_fixture_bundle(dir);
  std::ifstream in(dir / coupling::kBundleDataFile, std::ios::binary);
  std::string bytes(1, '\x01');  // mode byte: fix checksums after the edit
  bytes.append(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  const uint64_t huge = 1000000000000ull;
  std::memcpy(bytes.data() + 1 + 32 + 16, &huge, 8);  // element count of section 1
  const auto* p = reinterpret_cast<const uint8_t*>(bytes.data());
  expect_input_error_naming([&] { fuzz::load_mutated_bundle(dir, p, bytes.size()); },
                            coupling::kBundleDataFile);
}

}  // namespace
}  // namespace icd
