#pragma once
/// A small valid asset bundle for the bundle fuzz target and its regression
/// replay: an icosphere (1 subdivision) steered by a 2x2x2 box tet mesh, with
/// a 5-sphere tree (root + 4 children) associated with the surface nodes.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <icd/coupling/asset_bundle.hpp>
#include "tests/coupling/small_bundle.hpp"

namespace icd::fuzz {

/// Writes the fixture bundle into `folder` (dense_surface.vtu, coarse_tets.vtu,
/// bundle.icdb).
inline void write_fixture_bundle(const std::filesystem::path& folder) {
  coupling::write_asset_bundle(folder, coupling::make_small_bundle(1, 0.5));
}

/// Recomputes the total-size field and every checksum of bundle.icdb bytes
/// wherever the layout (coupling/asset_bundle.hpp) can still be followed.
inline void fix_bundle_checksums(std::string& s) {
  auto get64 = [&](size_t at) {
    uint64_t v;
    std::memcpy(&v, s.data() + at, 8);
    return v;
  };
  auto get32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, s.data() + at, 4);
    return v;
  };
  auto put64 = [&](size_t at, uint64_t v) { std::memcpy(s.data() + at, &v, 8); };
  if (s.size() < 32) return;
  put64(16, s.size());
  put64(24, coupling::fnv1a64(s.data(), 24));
  const uint32_t sections = get32(12);
  size_t at = 32;
  for (uint32_t k = 0; k < sections && at + 32 <= s.size(); ++k) {
    const uint64_t width = get32(at + 8) == 2 ? 8 : 4;
    const uint64_t count = get64(at + 16);
    if (count > (s.size() - at - 32) / width) return;
    const size_t bytes = static_cast<size_t>(count * width);
    put64(at + 24, coupling::fnv1a64(s.data() + at + 32, bytes));
    at += 32 + bytes;
  }
}

/// Replaces the bundle.icdb of `folder` by `input` (byte 0 = mode: odd ->
/// checksums fixed first) and loads it; returns the loaded bundle or throws.
inline coupling::AssetBundle load_mutated_bundle(const std::filesystem::path& folder,
                                                 const uint8_t* data, size_t size) {
  std::string bytes =
      size > 0 ? std::string(reinterpret_cast<const char*>(data) + 1, size - 1) : std::string();
  if (size > 0 && (data[0] & 1)) fix_bundle_checksums(bytes);
  {
    std::FILE* f = std::fopen((folder / coupling::kBundleDataFile).c_str(), "wb");
    if (f == nullptr) std::abort();
    std::fwrite(bytes.data(), 1, bytes.size(), f);
    std::fclose(f);
  }
  return coupling::read_asset_bundle(folder);
}

}  // namespace icd::fuzz
