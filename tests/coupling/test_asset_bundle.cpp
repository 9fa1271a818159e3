#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <icd/coupling/asset_bundle.hpp>
#include <icd/mesh/core/error.hpp>
#include "tests/coupling/small_bundle.hpp"

namespace icd::coupling {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("icd_bundle_" + name);
  fs::remove_all(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void spit(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << bytes;
}

// The bundle of small_bundle.hpp with a twice-subdivided icosphere.
AssetBundle make_bundle(double radius = 0.5) { return make_small_bundle(2, radius); }

void expect_same(const AssetBundle& a, const AssetBundle& b) {
  EXPECT_TRUE(a.dense.V == b.dense.V);  // bitwise: the VTU doubles read back exactly
  EXPECT_TRUE(a.dense.F == b.dense.F);
  EXPECT_TRUE(a.coarse.V == b.coarse.V);
  EXPECT_TRUE(a.coarse.T == b.coarse.T);
  EXPECT_TRUE(a.coarse.F == b.coarse.F);
  EXPECT_TRUE(a.surface_nodes == b.surface_nodes);
  EXPECT_TRUE(a.links.nodes == b.links.nodes);
  EXPECT_TRUE(a.links.alpha == b.links.alpha);
  EXPECT_TRUE(a.links.coeffs == b.links.coeffs);
  EXPECT_EQ(a.links.num_coarse_nodes, b.links.num_coarse_nodes);
  const auto& s = a.spheres;
  const auto& t = b.spheres;
  ASSERT_EQ(s.num_nodes(), t.num_nodes());
  for (int i = 0; i < s.num_nodes(); ++i) {
    EXPECT_EQ(s.spheres[i].center(), t.spheres[i].center());
    EXPECT_EQ(s.spheres[i].r, t.spheres[i].r);
    EXPECT_EQ(s.rest_spheres[i].r, t.rest_spheres[i].r);
  }
  EXPECT_EQ(s.first_child, t.first_child);
  EXPECT_EQ(s.child_count, t.child_count);
  EXPECT_EQ(s.level, t.level);
  EXPECT_EQ(s.level_offset, t.level_offset);
  EXPECT_EQ(s.assoc_offset, t.assoc_offset);
  EXPECT_EQ(s.assoc_nodes, t.assoc_nodes);
  EXPECT_EQ(s.assoc_rest_dist, t.assoc_rest_dist);
}

// Loading must fail with InputError whose message contains `fragment`.
void expect_refused(const fs::path& dir, const std::string& fragment) {
  try {
    read_asset_bundle(dir);
    ADD_FAILURE() << "no exception, expected '" << fragment << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(AssetBundle, Fnv1aReferenceValues) {
  // Published FNV-1a 64 test vectors.
  EXPECT_EQ(fnv1a64("", 0), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a64("foobar", 6), 0x85944171f73967e8ull);
}

TEST(AssetBundle, RoundTripIsExactAndDeterministic) {
  const AssetBundle b = make_bundle();
  const fs::path d1 = fresh_dir("rt1"), d2 = fresh_dir("rt2");
  write_asset_bundle(d1, b);
  write_asset_bundle(d2, make_bundle());
  const AssetBundle r = read_asset_bundle(d1);
  expect_same(b, r);
  for (const char* f : {kDenseSurfaceFile, kCoarseTetsFile, kBundleDataFile})
    EXPECT_EQ(slurp(d1 / f), slurp(d2 / f)) << f << " differs between identical bundles";
  // The loaded links still reproduce the dense mesh.
  MatX3d out(r.dense.V.rows(), 3);
  apply(r.links, r.coarse.V, out);
  EXPECT_LT((out - r.dense.V).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(AssetBundle, RoundTripWithoutSphereTree) {
  AssetBundle b = make_bundle();
  b.spheres = {};
  const fs::path d = fresh_dir("nosph");
  write_asset_bundle(d, b);
  const AssetBundle r = read_asset_bundle(d);
  EXPECT_EQ(r.spheres.num_nodes(), 0);
  EXPECT_TRUE(r.links.coeffs == b.links.coeffs);
}

TEST(AssetBundle, RefusesTruncatedFiles) {
  const fs::path d = fresh_dir("trunc");
  write_asset_bundle(d, make_bundle());
  const std::string good = slurp(d / kBundleDataFile);
  for (std::size_t len : {std::size_t{0}, std::size_t{5}, std::size_t{20}, std::size_t{40},
                          good.size() / 2, good.size() - 1}) {
    spit(d / kBundleDataFile, good.substr(0, len));
    expect_refused(d, len < 8 ? "bad magic" : "truncated");
  }
  spit(d / kBundleDataFile, good + "x");
  expect_refused(d, "trailing");
}

TEST(AssetBundle, RefusesCorruptedBytes) {
  const fs::path d = fresh_dir("corrupt");
  write_asset_bundle(d, make_bundle());
  const std::string good = slurp(d / kBundleDataFile);
  // Every single flipped bit in a sample of positions is detected.
  for (std::size_t pos = 0; pos < good.size(); pos += 37) {
    std::string bad = good;
    bad[pos] = static_cast<char>(bad[pos] ^ 0x10);
    spit(d / kBundleDataFile, bad);
    EXPECT_THROW(read_asset_bundle(d), InputError) << "flip at byte " << pos;
  }
  std::string bad = good;
  bad[good.size() - 3] ^= 0x01;  // inside the last payload
  spit(d / kBundleDataFile, bad);
  expect_refused(d, "checksum mismatch");
  bad = good;
  bad[0] = 'X';
  spit(d / kBundleDataFile, bad);
  expect_refused(d, "bad magic");
}

TEST(AssetBundle, RefusesOtherVersion) {
  const fs::path d = fresh_dir("version");
  write_asset_bundle(d, make_bundle());
  std::string bad = slurp(d / kBundleDataFile);
  const uint32_t v = kBundleFormatVersion + 1;
  std::memcpy(bad.data() + 8, &v, 4);
  const uint64_t h = fnv1a64(bad.data(), 24);  // a consistent header of another version
  std::memcpy(bad.data() + 24, &h, 8);
  spit(d / kBundleDataFile, bad);
  expect_refused(d, "format version 2 is not supported");
}

TEST(AssetBundle, RefusesMismatchedMeshesAndMissingFiles) {
  const fs::path d = fresh_dir("mismatch"), other = fresh_dir("other");
  write_asset_bundle(d, make_bundle(0.5));
  write_asset_bundle(other, make_bundle(0.45));  // same sizes, other coordinates
  fs::copy_file(other / kDenseSurfaceFile, d / kDenseSurfaceFile,
                fs::copy_options::overwrite_existing);
  expect_refused(d, "do not match");
  fs::remove(d / kDenseSurfaceFile);
  EXPECT_THROW(read_asset_bundle(d), InputError);
  expect_refused(fresh_dir("empty"), "cannot open");
}

TEST(AssetBundle, RefusesInconsistentBundleAtWrite) {
  AssetBundle b = make_bundle();
  b.links.alpha.conservativeResize(b.links.alpha.rows() - 1, 3);
  EXPECT_THROW(write_asset_bundle(fresh_dir("bad"), b), ParameterError);
  b = make_bundle();
  b.surface_nodes[0] = 10000;
  EXPECT_THROW(write_asset_bundle(fresh_dir("bad"), b), ParameterError);
}

}  // namespace
}  // namespace icd::coupling
