// libFuzzer target: icd::parse_vtu on arbitrary bytes. An accepted file must
// satisfy read_vtu's documented invariants (counts, offsets, index range,
// finite values); anything but a valid result or an InputError is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <icd/mesh/io/vtu_reader.hpp>
#include "tests/fuzz/fuzz_common.hpp"

namespace {

void check_vtu(const icd::VtuData& d) {
  using icd::fuzz::finding;
  const auto np = static_cast<int64_t>(d.points.rows());
  if (!d.points.allFinite()) finding("vtu: non-finite point accepted");
  if (d.offsets.size() != d.types.size()) finding("vtu: #offsets != #types");
  int64_t prev = 0;
  for (int64_t o : d.offsets) {
    if (o <= prev) finding("vtu: offsets not strictly increasing");
    prev = o;
  }
  if (!d.offsets.empty() && d.offsets.back() != static_cast<int64_t>(d.connectivity.size()))
    finding("vtu: last offset != connectivity size");
  for (int64_t c : d.connectivity)
    if (c < 0 || c >= np) finding("vtu: connectivity index out of range");
  for (const auto& a : d.point_data)
    if (a.values.rows() != np) finding("vtu: point data with the wrong row count");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  icd::fuzz::expect_clean([&] { check_vtu(icd::parse_vtu(bytes, "fuzz.vtu")); });
  return 0;
}
