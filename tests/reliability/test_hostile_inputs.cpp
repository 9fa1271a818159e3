// Hostile and unusual inputs a new user (or an attacker handing over a file)
// tries: a byte-order mark in every text format, counts that disagree with
// the data, files that are folders or devices, files far above the size
// limits, raw bytes in messages, numbers beyond the double range, options that
// contradict each other. Oracle: the documented contract -- the same result
// as without the byte-order mark, or an InputError naming the file (and the
// field) without raw bytes, quickly and without reading the whole file.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <icd/collision/sph_io.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/vtu_reader.hpp>
#include "experiments/runner/scene.hpp"
#include "tests/fuzz/bundle_fixture.hpp"

namespace icd {
namespace {

namespace fs = std::filesystem;

const std::string kBom = "\xEF\xBB\xBF";

// The message of the InputError `f` throws ("" and a test failure if none).
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << typeid(e).name() << ": " << e.what();
    return "";
  }
  ADD_FAILURE() << "accepted";
  return "";
}

// Every byte of a message is printable ASCII (raw input bytes are escaped).
void expect_printable(const std::string& msg) {
  for (const char c : msg) {
    const auto u = static_cast<unsigned char>(c);
    EXPECT_TRUE(u >= 0x20 && u < 0x7f) << "raw byte 0x" << std::hex << int{u} << " in: " << msg;
  }
}

void expect_same(const SurfaceMesh& a, const SurfaceMesh& b) {
  EXPECT_EQ(a.V.rows(), b.V.rows());
  EXPECT_EQ(a.F.rows(), b.F.rows());
  if (a.V.rows() == b.V.rows()) {
    EXPECT_EQ(a.V, b.V);
  }
  if (a.F.rows() == b.F.rows()) {
    EXPECT_EQ(a.F, b.F);
  }
}

const char* kTetObj =
    "# tet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
const char* kTetOff =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
const char* kTetPly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

std::string ascii_stl() {
  const char* facets[4][3] = {{"0 0 0", "0 1 0", "1 0 0"},
                              {"0 0 0", "1 0 0", "0 0 1"},
                              {"0 0 0", "0 0 1", "0 1 0"},
                              {"1 0 0", "0 1 0", "0 0 1"}};
  std::string s = "solid tet\n";
  for (const auto& f : facets) {
    s += "facet normal 0 0 0\nouter loop\n";
    for (const char* v : f) s += std::string("vertex ") + v + "\n";
    s += "endloop\nendfacet\n";
  }
  return s + "endsolid tet\n";
}

// A binary STL whose header announces `announced` triangles and that holds
// `held` (distinct, non-degenerate) triangles.
std::string binary_stl(uint32_t announced, uint32_t held) {
  std::string s(80, ' ');
  s.append(reinterpret_cast<const char*>(&announced), 4);
  for (uint32_t t = 0; t < held; ++t) {
    const float f[12] = {0, 0, 1, float(t), 0, 0, float(t) + 1, 0, 0, float(t), 1, 0};
    s.append(reinterpret_cast<const char*>(f), sizeof f);
    s.append(2, '\0');
  }
  return s;
}

// --- byte-order marks ---------------------------------------------------

TEST(HostileInputs, ObjWithAByteOrderMarkKeepsItsFirstVertex) {
  const SurfaceMesh plain = parse_obj(kTetObj, "tet.obj");
  // The mark on the first vertex line (no comment before it).
  const std::string first_v = std::string(kTetObj).substr(std::string("# tet\n").size());
  expect_same(parse_obj(kBom + first_v, "bom.obj"), plain);
  expect_same(parse_obj(kBom + kTetObj, "bom.obj"), plain);
}

TEST(HostileInputs, EveryTextFormatAcceptsAByteOrderMark) {
  expect_same(parse_off(kBom + kTetOff, "bom.off"), parse_off(kTetOff, "tet.off"));
  expect_same(parse_ply(kBom + kTetPly, "bom.ply"), parse_ply(kTetPly, "tet.ply"));
  expect_same(parse_stl(kBom + ascii_stl(), "bom.stl"), parse_stl(ascii_stl(), "tet.stl"));
  // Binary PLY: the mark before the (text) header.
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  bin.append(reinterpret_cast<const char*>(v), sizeof v);
  bin += '\3';
  const int32_t f[3] = {0, 1, 2};
  bin.append(reinterpret_cast<const char*>(f), sizeof f);
  expect_same(parse_ply(kBom + bin, "bom_bin.ply"), parse_ply(bin, "bin.ply"));

  const std::string sph = "2 2\n0 0 0 2 0\n-1 0 0 1 0\n1 0 0 1 0\n";
  std::istringstream plain(sph), marked(kBom + sph);
  EXPECT_EQ(collision::read_sph(marked, "bom.sph").num_nodes(),
            collision::read_sph(plain, "tree.sph").num_nodes());

  const runner::Json j = runner::parse_json(kBom + R"({"a": 1})", "bom.json");
  EXPECT_EQ(j.at("a").get<double>(), 1.0);
}

// --- counts that disagree with the data ------------------------------------

TEST(HostileInputs, BinaryStlSizeMustMatchItsTriangleCount) {
  // Header count 10, 320 triangles of data: not 10 triangles read silently.
  const std::string msg = input_error([] { parse_stl(binary_stl(10, 320), "short_count.stl"); });
  EXPECT_NE(msg.find("short_count.stl"), std::string::npos) << msg;
  EXPECT_NE(msg.find("84 + 50"), std::string::npos) << msg;
  // A few bytes after the last triangle: also not the size of a binary STL.
  std::string tail = binary_stl(1, 1) + "abc";
  EXPECT_NE(input_error([&] { parse_stl(tail, "tail.stl"); }).find("tail.stl"), std::string::npos);
  EXPECT_EQ(parse_stl(binary_stl(3, 3), "ok.stl").F.rows(), 3);
}

TEST(HostileInputs, OffWithMoreFacesThanItsHeaderIsRefused) {
  const std::string off = "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n";
  const std::string msg = input_error([&] { parse_off(off, "extra_faces.off"); });
  EXPECT_NE(msg.find("extra_faces.off: line 8"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1 face"), std::string::npos) << msg;
}

// --- files that are not what they claim -------------------------------------

TEST(HostileInputs, BundleFileThatIsAFolderIsRefused) {
  const fs::path dir = fs::path(::testing::TempDir()) / "icd_hostile_bundle_dir";
  fs::remove_all(dir);
  fuzz::write_fixture_bundle(dir);
  fs::remove(dir / coupling::kBundleDataFile);
  fs::create_directories(dir / coupling::kBundleDataFile);
  const std::string msg = input_error([&] { coupling::read_asset_bundle(dir); });
  EXPECT_NE(msg.find("bundle.icdb: cannot open file: not a regular file"), std::string::npos)
      << msg;
}

TEST(HostileInputs, SceneFileThatIsADeviceIsRefusedWithoutReading) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string msg = input_error([] { runner::read_json_file("/dev/zero"); });
  EXPECT_NE(msg.find("/dev/zero: cannot open file: not a regular file"), std::string::npos) << msg;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
}

// A 1.5 GB file of NUL bytes (sparse: no disk space used) is refused by its
// size, before a byte is read; so is a mesh far above its limit.
TEST(HostileInputs, FilesAboveTheirSizeLimitAreRefusedBeforeReading) {
  const fs::path dir = fs::path(::testing::TempDir()) / "icd_hostile_big";
  fs::create_directories(dir);
  const auto sparse = [&](const std::string& name, std::uintmax_t size) {
    const fs::path p = dir / name;
    std::ofstream(p).close();
    fs::resize_file(p, size);
    return p;
  };
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path scene = sparse("nul.json", 1536ull << 20);
  std::string msg = input_error([&] { runner::read_json_file(scene.string()); });
  EXPECT_NE(msg.find("nul.json: scene file of 1610612736 bytes"), std::string::npos) << msg;
  EXPECT_NE(msg.find("limit"), std::string::npos) << msg;
  expect_printable(msg);
  const fs::path mesh = sparse("nul.off", 1536ull << 20);
  msg = input_error([&] { read_surface_mesh(mesh); });
  EXPECT_NE(msg.find("nul.off: mesh of 1610612736 bytes"), std::string::npos) << msg;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
  fs::remove_all(dir);
}

// --- messages ---------------------------------------------------------------

TEST(HostileInputs, JsonMessagesEscapeRawBytes) {
  for (const std::string& text :
       {std::string("{\"a\": \0}", 8), std::string("\xEF\xBB{}"), std::string("{\"a\": \xFF}"),
        std::string("{\"\\u0000\": 1, "
                    "\"\\u0000\": 2}")}) {
    const std::string msg = input_error([&] { runner::parse_json(text, "raw.json"); });
    EXPECT_EQ(msg.rfind("raw.json:", 0), 0u) << msg;
    expect_printable(msg);
  }
}

// --- scene fields -------------------------------------------------------------

runner::Scene parse_scene_text(const std::string& text) {
  return runner::parse_scene(runner::parse_json(text, "s.json"), "s.json", ".");
}

TEST(HostileInputs, NumberBeyondTheDoubleRangeNamesTheField) {
  const std::string msg = input_error([] {
    parse_scene_text(R"({"objects": [{"primitive": {}, "material": {"young": 1e400}}]})");
  });
  EXPECT_NE(msg.find("s.json: objects[0].material.young:"), std::string::npos) << msg;
  // Tiny numbers are simply 0 (here refused by the field's range).
  const std::string tiny = input_error([] {
    parse_scene_text(R"({"objects": [{"primitive": {}, "material": {"young": 1e-400}}]})");
  });
  EXPECT_NE(tiny.find("objects[0].material.young: must be in (0"), std::string::npos) << tiny;
}

TEST(HostileInputs, ContradictoryBudgetsAreRefusedNamingBoth) {
  for (const char* collision : {R"({"budget_tests": 100, "budget_seconds": 0.001})",
                                R"({"unlimited": true, "budget_seconds": 0.001})",
                                R"({"unlimited": true, "budget_tests": 100})"}) {
    const std::string msg = input_error([&] {
      parse_scene_text(std::string(R"({"objects": [{"primitive": {}}], "collision": )") +
                       collision + "}");
    });
    EXPECT_NE(msg.find("s.json: collision"), std::string::npos) << msg;
    int named = 0;
    for (const char* k : {"budget_tests", "budget_seconds", "unlimited"})
      named += msg.find(k) != std::string::npos;
    EXPECT_EQ(named, 2) << collision << " -> " << msg;
  }
}

}  // namespace
}  // namespace icd
