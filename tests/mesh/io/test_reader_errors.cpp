// Every bad case of the readers gets an InputError whose message names the
// file and the reason (and the line where meaningful); nothing crashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include "io_test_util.hpp"
#include <icd/mesh/io/surface_reader.hpp>

namespace icd {
namespace {

using test::expect_contains_all;
using test::input_error_message;
using test::TempDir;
using test::write_bytes;

// Writes `text` to dir/name, reads it, and checks the error message parts.
void expect_read_error(const TempDir& dir, const std::string& name, const std::string& text,
                       std::initializer_list<std::string_view> parts) {
  SCOPED_TRACE(name);
  const auto path = write_bytes(dir / name, text);
  const std::string msg = input_error_message([&] { read_surface_mesh(path); });
  expect_contains_all(msg, {name});
  expect_contains_all(msg, parts);
  // The message starts with the file path.
  EXPECT_EQ(msg.rfind(path.string(), 0), 0u) << msg;
}

const char* const kTriOff = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

TEST(ReaderErrors, MissingFileAndUnknownExtension) {
  TempDir dir;
  std::string msg = input_error_message([&] { read_surface_mesh(dir / "nope.off"); });
  expect_contains_all(msg, {"nope.off", "no such file"});
  msg = input_error_message([&] { read_surface_mesh(dir.path()); });
  expect_contains_all(msg, {"not a regular file"});
  write_bytes(dir / "mesh.xyz", kTriOff);
  msg = input_error_message([&] { read_surface_mesh(dir / "mesh.xyz"); });
  expect_contains_all(msg, {"mesh.xyz", "unknown mesh file extension", ".xyz"});
  write_bytes(dir / "noext", kTriOff);
  msg = input_error_message([&] { read_surface_mesh(dir / "noext"); });
  expect_contains_all(msg, {"noext", "unknown mesh file extension"});
}

TEST(ReaderErrors, Off) {
  TempDir dir;
  ASSERT_EQ(read_surface_mesh(write_bytes(dir / "ok.off", kTriOff)).F.rows(), 1);
  expect_read_error(dir, "empty.off", "", {"truncated", "empty"});
  expect_read_error(dir, "header.off", "OFX\n3 1 0\n", {"line 1", "not an OFF file"});
  expect_read_error(dir, "trunc_v.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n", {"truncated", "vertex 2"});
  expect_read_error(dir, "trunc_f.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                    {"truncated", "face 1"});
  expect_read_error(dir, "short_face.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
                    {"line 6", "face 0", "expected 3 vertex indices"});
  expect_read_error(dir, "nonnum.off", "OFF\n3 1 0\n0 0 0\n1 abc 0\n0 1 0\n3 0 1 2\n",
                    {"line 4", "vertex 1", "'abc'", "not a number"});
  expect_read_error(dir, "trailing.off", "OFF\n3 1 0\n0 0 0\n1 0x 0\n0 1 0\n3 0 1 2\n",
                    {"line 4", "'0x'", "not a number"});
  expect_read_error(dir, "nan.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n",
                    {"line 5", "vertex 2", "NaN"});
  expect_read_error(dir, "inf.off", "OFF\n3 1 0\n0 0 0\n1 0 -inf\n0 1 0\n3 0 1 2\n",
                    {"line 4", "vertex 1", "infinite"});
  expect_read_error(dir, "huge.off", "OFF\n3 1 0\n0 0 0\n1 0 1e999\n0 1 0\n3 0 1 2\n",
                    {"line 4", "out of the double range"});
  expect_read_error(dir, "range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
                    {"line 6", "face 0", "index 3", "out of range"});
  expect_read_error(dir, "neg.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
                    {"line 6", "face 0", "index -1", "out of range"});
  expect_read_error(dir, "idx.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n",
                    {"line 6", "'1.5'", "not an integer"});
  expect_read_error(dir, "two.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
                    {"line 6", "face 0", "has 2 vertices"});
  expect_read_error(dir, "novert.off", "OFF\n0 0 0\n", {"empty mesh", "no vertices"});
  expect_read_error(dir, "noface.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n",
                    {"empty mesh", "no faces"});
  expect_read_error(dir, "counts.off", "OFF\n3 x 0\n", {"line 2", "number of faces", "'x'"});
  expect_read_error(dir, "negcount.off", "OFF\n-3 1 0\n", {"line 2", "negative"});
  expect_read_error(dir, "extra.off", "OFF\n3 1 0\n0 0 0 7\n1 0 0\n0 1 0\n3 0 1 2\n",
                    {"line 3", "unexpected token '7'"});
}

TEST(ReaderErrors, HugeHeaderCountsFailFast) {
  TempDir dir;
  // ~20-byte files claiming 10^12 (or 2*10^9, which fits in int32) vertices.
  expect_read_error(dir, "big.off", "OFF\n1000000000000 1 0\n", {"line 2", "1000000000000"});
  expect_read_error(dir, "big2.off", "OFF\n2000000000 1 0\n",
                    {"line 2", "truncated", "2000000000 vertices"});
  expect_read_error(dir, "bigf.off", "OFF\n3 2000000000 0\n0 0 0\n1 0 0\n0 1 0\n",
                    {"line 2", "truncated", "2000000000 faces"});
  expect_read_error(dir, "big.ply",
                    "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
                    "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                    "property list uchar int vertex_indices\nend_header\n",
                    {"line 3", "1000000000000"});
  expect_read_error(
      dir, "big2.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nelement face 2000000000\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0\n",
      {"line 7", "truncated", "2000000000"});
  expect_read_error(dir, "bigother.ply",
                    "ply\nformat binary_big_endian 1.0\nelement vertex 3\n"
                    "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                    "property list uchar int vertex_indices\nelement junk 4000000000000000\n"
                    "property double a\nend_header\n" +
                        std::string(3 * 12 + 13, '\0'),
                    {"line 9", "truncated", "'junk'"});
  std::string stl(84, '\0');
  const uint32_t n = 4000000000u;
  for (int b = 0; b < 4; ++b) stl[80 + b] = static_cast<char>((n >> (8 * b)) & 0xff);
  expect_read_error(dir, "big.stl", stl, {"truncated", "4000000000 triangles"});
  // The messages come from the header check, which runs before any allocation
  // or per-element loop sized by the count.
}

TEST(ReaderErrors, Obj) {
  TempDir dir;
  expect_read_error(dir, "empty.obj", "# nothing\n", {"empty mesh", "no vertices"});
  expect_read_error(dir, "nofaces.obj", "v 0 0 0\nv 1 0 0\n", {"empty mesh", "no faces"});
  expect_read_error(dir, "nonnum.obj", "v 0 0 0\nv 1 zz 0\n", {"line 2", "vertex 1", "'zz'"});
  expect_read_error(dir, "short.obj", "v 0 0 0\nv 1 0\n", {"line 2", "expected 3 coordinates"});
  expect_read_error(dir, "nan.obj", "v 0 0 0\nv 1 0 NaN\nv 0 1 0\nf 1 2 3\n",
                    {"line 2", "vertex 1", "NaN"});
  expect_read_error(dir, "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
                    {"line 4", "face 0", "index 3", "out of range"});
  expect_read_error(dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
                    {"line 4", "face 0", "'0'", "out of range"});
  expect_read_error(dir, "neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
                    {"line 4", "face 0", "-4", "out of range"});
  expect_read_error(dir, "two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
                    {"line 4", "face 0", "has 2 vertices"});
  expect_read_error(dir, "badidx.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 b 3\n",
                    {"line 4", "'b'", "not an integer"});
  // A binary blob renamed .obj: rejected, not read as a mesh of nothing.
  std::string junk;
  std::mt19937 rng(0);
  for (int i = 0; i < 4000; ++i) junk += static_cast<char>(rng() % 256);
  const auto path = write_bytes(dir / "junk.obj", junk);
  expect_contains_all(input_error_message([&] { read_surface_mesh(path); }), {"junk.obj"});
}

std::string ply_header(const std::string& format, int nv, int nf) {
  return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(nv) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(nf) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

TEST(ReaderErrors, PlyAscii) {
  TempDir dir;
  const std::string h = ply_header("ascii", 3, 1);
  ASSERT_EQ(
      read_surface_mesh(write_bytes(dir / "ok.ply", h + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).F.rows(),
      1);
  expect_read_error(dir, "magic.ply", "plx\n", {"line 1", "not a PLY file"});
  expect_read_error(dir, "noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n",
                    {"no 'end_header'"});
  expect_read_error(dir, "fmt.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n",
                    {"line 2", "unknown PLY format"});
  expect_read_error(dir, "type.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n",
                    {"line 4", "unknown property type 'quad'"});
  expect_read_error(dir, "noz.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                    "property float y\nend_header\n0 0\n",
                    {"line 3", "no property 'z'"});
  expect_read_error(dir, "noface.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                    "property float z\nend_header\n0 0 0\n",
                    {"empty mesh", "no 'face' element"});
  expect_read_error(dir, "trunc.ply", h + "0 0 0\n1 0 0\n0 1\n", {"truncated", "vertex 2", "'z'"});
  expect_read_error(dir, "trunc_f.ply", h + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
                    {"truncated", "face 0"});
  expect_read_error(dir, "nonnum.ply", h + "0 0 0\n1 q 0\n0 1 0\n3 0 1 2\n",
                    {"line 11", "vertex 1", "'q'", "not a number"});
  expect_read_error(dir, "nan.ply", h + "0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n",
                    {"line 12", "vertex 2", "NaN"});
  expect_read_error(dir, "range.ply", h + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
                    {"line 13", "face 0", "index 3", "out of range"});
  expect_read_error(dir, "neg.ply", h + "0 0 0\n1 0 0\n0 1 0\n3 0 -2 1\n",
                    {"line 13", "face 0", "index -2", "out of range"});
  expect_read_error(dir, "two.ply", h + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
                    {"line 13", "face 0", "has 2 vertices"});
  expect_read_error(dir, "empty.ply", ply_header("ascii", 0, 0), {"empty mesh"});
}

// Little-endian bytes of a 4-byte value, on any host.
template <class T>
std::string le_bytes(T v) {
  static_assert(sizeof(T) == 4);
  std::string s(4, '\0');
  std::memcpy(s.data(), &v, 4);
  if constexpr (std::endian::native == std::endian::big) std::reverse(s.begin(), s.end());
  return s;
}
std::string le_float(float v) { return le_bytes(v); }
std::string le_int(int32_t v) { return le_bytes(v); }

TEST(ReaderErrors, PlyBinary) {
  TempDir dir;
  const std::string h = ply_header("binary_little_endian", 3, 1);
  std::string verts;
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) verts += le_float(v);
  const auto face = [](int a, int b, int c) {
    return std::string(1, '\3') + le_int(a) + le_int(b) + le_int(c);
  };
  ASSERT_EQ(read_surface_mesh(write_bytes(dir / "ok.ply", h + verts + face(0, 1, 2))).F.rows(), 1);
  expect_read_error(dir, "trunc.ply", h + verts + face(0, 1, 2).substr(0, 9),
                    {"truncated", "face 0"});
  expect_read_error(dir, "truncv.ply", h + verts.substr(0, 30), {"truncated"});
  expect_read_error(dir, "range.ply", h + verts + face(0, 1, 7),
                    {"face 0", "index 7", "out of range"});
  expect_read_error(dir, "neg.ply", h + verts + face(0, -1, 2),
                    {"face 0", "index -1", "out of range"});
  std::string nan_verts = verts;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  nan_verts.replace(16, 4, le_float(nan));
  expect_read_error(dir, "nan.ply", h + nan_verts + face(0, 1, 2), {"vertex 1", "NaN"});
  std::string inf_verts = verts;
  inf_verts.replace(0, 4, le_float(std::numeric_limits<float>::infinity()));
  expect_read_error(dir, "inf.ply", h + inf_verts + face(0, 1, 2), {"vertex 0", "infinite"});
  expect_read_error(dir, "two.ply", h + verts + std::string(1, '\2') + le_int(0) + le_int(1),
                    {"face 0", "has 2 vertices"});
}

std::string binary_stl(int n_declared, const std::vector<float>& corners) {
  std::string s(80, 'x');
  s += le_int(n_declared);
  for (size_t t = 0; t * 9 < corners.size(); ++t) {
    s += le_float(0) + le_float(0) + le_float(1);
    for (size_t k = 0; k < 9; ++k) s += le_float(corners[9 * t + k]);
    s += std::string(2, '\0');
  }
  return s;
}

TEST(ReaderErrors, Stl) {
  TempDir dir;
  const std::vector<float> tri = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  ASSERT_EQ(read_surface_mesh(write_bytes(dir / "ok.stl", binary_stl(1, tri))).F.rows(), 1);
  expect_read_error(dir, "short.stl", "abc", {"truncated", "too short"});
  expect_read_error(dir, "trunc.stl", binary_stl(2, tri), {"truncated", "2 triangles"});
  expect_read_error(dir, "zero.stl", binary_stl(0, {}), {"empty mesh"});
  std::vector<float> bad = tri;
  bad[4] = std::numeric_limits<float>::quiet_NaN();
  expect_read_error(dir, "nan.stl", binary_stl(1, bad), {"vertex 1", "NaN"});
  const std::string a = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n";
  expect_read_error(dir, "trunc_a.stl", a, {"truncated", "facet 0"});
  expect_read_error(dir, "nonnum_a.stl", a + "vertex 0 one 0\nendloop\nendfacet\nendsolid t\n",
                    {"line 6", "facet 0", "'one'", "not a number"});
  expect_read_error(dir, "inf_a.stl", a + "vertex 0 inf 0\nendloop\nendfacet\nendsolid t\n",
                    {"line 6", "vertex 2", "infinite"});
  expect_read_error(dir, "two_a.stl", a + "endloop\nendfacet\nendsolid t\n",
                    {"line 2", "face 0", "has 2 vertices"});
  expect_read_error(dir, "noend_a.stl", a + "vertex 0 1 0\nendloop\nendfacet\n",
                    {"truncated", "endsolid"});
  expect_read_error(dir, "kw_a.stl", a + "vertex 0 1 0\nendloop\nendfacet\nfoo\n",
                    {"line 9", "'foo'"});
  expect_read_error(dir, "empty_a.stl", "solid empty\nendsolid empty\n", {"empty mesh"});
}

// Robustness: every prefix and many random byte corruptions of valid files
// either read or throw InputError; nothing else (no crash, no other exception).
TEST(ReaderErrors, TruncationsAndCorruptionsNeverCrash) {
  const std::string h = ply_header("binary_big_endian", 3, 1);
  std::string be_verts;
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) {
    std::string f = le_float(v);
    std::reverse(f.begin(), f.end());
    be_verts += f;
  }
  const std::string be_face = std::string("\3\0\0\0\0\0\0\0\1\0\0\0\2", 13);
  const std::vector<std::pair<std::string, std::string>> files = {
      {"off", kTriOff},
      {"obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"ply", ply_header("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
      {"ply", h + be_verts + be_face},
      {"stl", binary_stl(1, {0, 0, 0, 1, 0, 0, 0, 1, 0})},
      {"stl",
       "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
       "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n"}};
  std::mt19937 rng(0);
  int read_ok = 0, rejected = 0;
  for (const auto& [ext, text] : files) {
    const auto parse = [&](std::string_view bytes) {
      if (ext == "off") return parse_off(bytes, "x.off");
      if (ext == "obj") return parse_obj(bytes, "x.obj");
      if (ext == "ply") return parse_ply(bytes, "x.ply");
      return parse_stl(bytes, "x.stl");
    };
    auto attempt = [&](const std::string& bytes) {
      try {
        const SurfaceMesh m = parse(bytes);
        ASSERT_GE(m.F.rows(), 1);
        ASSERT_TRUE(m.V.allFinite());
        ASSERT_GE(m.F.minCoeff(), 0);
        ASSERT_LT(m.F.maxCoeff(), m.V.rows());
        ++read_ok;
      } catch (const InputError& e) {
        ASSERT_EQ(std::string(e.what()).rfind("x." + ext + ": ", 0), 0u) << e.what();
        ++rejected;
      }
    };
    for (size_t len = 0; len < text.size(); ++len) attempt(text.substr(0, len));
    for (int trial = 0; trial < 300; ++trial) {
      std::string bytes = text;
      const int flips = 1 + static_cast<int>(rng() % 3);
      for (int k = 0; k < flips; ++k) bytes[rng() % bytes.size()] = static_cast<char>(rng() % 256);
      attempt(bytes);
    }
  }
  EXPECT_GT(read_ok, 0);
  EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace icd
