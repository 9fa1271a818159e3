// libFuzzer target: scene files, icd::runner::parse_json then parse_scene.
// Either both succeed or one throws InputError/ParameterError naming the
// source; anything else is a finding. No file is read: mesh/asset paths are
// only resolved, never opened, by parse_scene.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "experiments/runner/scene.hpp"
#include "tests/fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  icd::fuzz::expect_clean([&] {
    const icd::runner::Json json = icd::runner::parse_json(text, "fuzz.json");
    const icd::runner::Scene scene = icd::runner::parse_scene(json, "fuzz.json", "/nonexistent");
    if (scene.frames < 0 || !(scene.world.frame_rate > 0))
      icd::fuzz::finding("scene: absurd frames accepted");
  });
  return 0;
}
