#pragma once
/// Shared checks of the libFuzzer targets: a reader may accept an input (and
/// then its result must satisfy the documented postconditions) or refuse it
/// with icd::InputError / icd::ParameterError; any other exception, a crash or
/// a sanitizer report is a finding.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <typeinfo>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::fuzz {

/// Aborts (so libFuzzer records the input) with `what` on stderr.
[[noreturn]] inline void finding(const char* what) {
  std::fprintf(stderr, "FUZZ FINDING: %s\n", what);
  std::abort();
}

/// Runs `parse()`; documented errors are fine, anything else is a finding.
template <class F>
void expect_clean(F&& parse) {
  try {
    parse();
  } catch (const icd::InputError&) {
  } catch (const icd::ParameterError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "undocumented exception %s: %s\n", typeid(e).name(), e.what());
    finding("a reader threw an exception other than InputError/ParameterError");
  }
}

/// Postconditions of every surface reader (mesh/io/surface_reader.hpp).
inline void check_surface(const SurfaceMesh& m) {
  if (m.V.rows() < 1 || m.F.rows() < 1) finding("surface reader returned an empty mesh");
  if (!m.V.allFinite()) finding("surface reader returned a non-finite coordinate");
  if (m.F.minCoeff() < 0 || m.F.maxCoeff() >= m.V.rows())
    finding("surface reader returned an out-of-range face index");
}

}  // namespace icd::fuzz
