// libFuzzer target: icd::collision::read_sph on arbitrary bytes. An accepted
// tree must have finite spheres with r >= 0 and a consistent topology.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include <icd/collision/sph_io.hpp>
#include "tests/fuzz/fuzz_common.hpp"

namespace {

void check_tree(const icd::collision::SphereTree& t) {
  using icd::fuzz::finding;
  const int n = t.num_nodes();
  if (n < 1) finding("sph: empty tree accepted");
  if (t.rest_spheres.size() != t.spheres.size()) finding("sph: rest_spheres size differs");
  for (const auto& s : t.spheres)
    if (!(s.r >= 0) || !std::isfinite(s.r) || !s.center().allFinite())
      finding("sph: non-finite or negative sphere accepted");
  if (static_cast<int>(t.first_child.size()) != n || static_cast<int>(t.child_count.size()) != n)
    finding("sph: topology arrays of the wrong size");
  try {
    icd::collision::validate(t);  // the library's own invariant check must agree
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    finding("sph: read_sph accepted a tree that validate() refuses");
  }
  for (int i = 0; i < n; ++i) {
    if (t.child_count[i] < 0) finding("sph: negative child count");
    if (t.child_count[i] > 0 && (t.first_child[i] <= i || t.first_child[i] + t.child_count[i] > n))
      finding("sph: child range out of bounds");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  icd::fuzz::expect_clean([&] { check_tree(icd::collision::read_sph(in, "fuzz.sph")); });
  return 0;
}
