// libFuzzer target: icd::coupling::read_asset_bundle. At start-up a small
// valid bundle (icosphere on a 2x2x2 box tet mesh, 5-sphere tree) is written to
// a temporary folder; each input replaces its bundle.icdb and the folder is
// loaded. Input byte 0 is a mode byte: when odd, the remaining bytes get their
// total-size field and every checksum recomputed before writing, so mutations
// reach the content checks behind the checksums. A loaded bundle must be
// consistent; an InputError/ParameterError is fine; anything else is a finding.
// Env ICD_FUZZ_SEED_OUT=<dir>: also write the valid bundle.icdb (with mode
// byte 1) there as a seed.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <icd/coupling/asset_bundle.hpp>
#include "tests/fuzz/bundle_fixture.hpp"
#include "tests/fuzz/fuzz_common.hpp"

namespace {

namespace fs = std::filesystem;

fs::path make_folder() {
  const fs::path dir =
      fs::temp_directory_path() / ("icd_fuzz_bundle_" + std::to_string(::getpid()));
  icd::fuzz::write_fixture_bundle(dir);
  if (const char* seed_dir = std::getenv("ICD_FUZZ_SEED_OUT")) {
    std::ifstream in(dir / icd::coupling::kBundleDataFile, std::ios::binary);
    std::string bytes(1, '\x01');
    bytes.append(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    fs::create_directories(seed_dir);
    std::ofstream(fs::path(seed_dir) / "valid.icdb", std::ios::binary) << bytes;
  }
  return dir;
}

void check_bundle(const icd::coupling::AssetBundle& b) {
  using icd::fuzz::finding;
  const auto nd = b.dense.V.rows(), nc = b.coarse.V.rows();
  if (b.links.nodes.rows() != nd) finding("bundle: one link per dense vertex violated");
  if (b.links.nodes.size() > 0 && (b.links.nodes.minCoeff() < 0 || b.links.nodes.maxCoeff() >= nc))
    finding("bundle: link node out of range");
  if (b.surface_nodes.size() > 0 &&
      (b.surface_nodes.minCoeff() < 0 || b.surface_nodes.maxCoeff() >= nc))
    finding("bundle: surface node out of range");
  if (!b.links.alpha.allFinite() || !b.links.coeffs.allFinite()) finding("bundle: non-finite link");
  if (b.spheres.num_nodes() > 0) {
    try {
      icd::collision::validate(b.spheres);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s\n", e.what());
      finding("bundle: loaded sphere tree fails validate()");
    }
    for (int32_t n : b.spheres.assoc_nodes)
      if (n < 0 || n >= nc) finding("bundle: sphere association out of range");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const fs::path folder = make_folder();
  icd::fuzz::expect_clean(
      [&] { check_bundle(icd::fuzz::load_mutated_bundle(folder, data, size)); });
  return 0;
}
