#pragma once
/// Loops of the 8-lane kernels (lane_kernels.hpp) over a range of elements,
/// compiled twice: for the baseline x86-64 instruction set (SSE2: 2 doubles
/// per instruction) and for AVX2 (4 doubles), chosen at run time from what the
/// CPU supports. Both run the same operations in the same order (no FMA
/// contraction), so their results are bitwise identical.
#include <icd/fem/lane_kernels.hpp>

namespace icd::fem::lanes {

/// Instruction set of the lane loops.
enum class LaneIsa {
  Baseline,  ///< the compiler's default target (x86-64: SSE2)
  AVX2       ///< only where the CPU supports it (x86 only)
};

/// The instruction set in use: AVX2 where the CPU has it, unless set_lane_isa() chose otherwise.
LaneIsa lane_isa();
/// Chooses the instruction set for the whole process (benchmarks and tests
/// compare them); returns false and changes nothing if the CPU lacks it. Not
/// thread-safe: call it while no force evaluation runs.
bool set_lane_isa(LaneIsa isa);
/// "baseline" or "avx2".
const char* to_string(LaneIsa isa);

/// What the lane loops read and write. Forces go either straight into
/// `forces` (#V x 3 row-major, accumulated in element order) or, when it is
/// null, into `element_forces` (#T x 12, the threaded path's buffer).
struct LaneLoopInput {
  const double* x = nullptr;      ///< positions (#V x 3 row-major), m
  const int* tets = nullptr;      ///< #T x 4
  const Block* blocks = nullptr;  ///< one per 8 elements
  double mu = 0, lambda = 0;      ///< Lame parameters, Pa
  double* forces = nullptr;
  double* element_forces = nullptr;
};

/// Health of a range of elements from the force loops (LaneCheck Full:
/// energy, min_det and min_element; Orientation: oriented only).
struct LaneRangeHealth {
  double energy = 0;     ///< sum V_e psi_e, in lane order (deterministic), J
  double min_det = 0;    ///< smallest det F (+inf for an empty range)
  int min_element = -1;  ///< its element (the smallest index on ties)
  /// Orientation: true iff det F > 0 for every element of the range (false
  /// where one is <= 0 or NaN).
  bool oriented = true;
};

/// Elastic forces of elements [begin, end) (begin a multiple of kLanes) of a
/// Linear, StVK or StableNeoHookean mesh; with kCheck also their health
/// (LaneRangeHealth). Bitwise equal for either LaneIsa.
template <MaterialModel kModel, LaneCheck kCheck>
void force_range(const LaneLoopInput& in, int begin, int end, LaneRangeHealth* health);

/// Force differentials -K(x) dx of elements [begin, end) (dx #V x 3 row-major), written like
/// force_range().
template <MaterialModel kModel>
void differential_range(const LaneLoopInput& in, const double* dx, int begin, int end);

}  // namespace icd::fem::lanes
