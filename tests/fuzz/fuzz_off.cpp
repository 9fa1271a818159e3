// libFuzzer target: icd::parse_off on arbitrary bytes. Accepts a valid mesh
// (postconditions checked) or an InputError; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <icd/mesh/io/surface_reader.hpp>
#include "tests/fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  icd::fuzz::expect_clean([&] { icd::fuzz::check_surface(icd::parse_off(bytes, "fuzz.off")); });
  return 0;
}
