#pragma once
/// Boundary-sample exchange between neighbouring spheres: a sphere hands the
/// samples that set its radius to a neighbour that already covers them, then
/// shrinks. Lowers errors without raising any (sphere-tree refinement step).
#include <functional>
#include <vector>

#include "mesh/spheres/reduction.hpp"

namespace icd::mesh {

/// Options of shrink_by_exchange().
struct ExchangeOptions {
  int rounds = 3;  ///< passes over all spheres (>= 0); stops early when a pass moves nothing
  /// Samples tried per sphere and pass, farthest first (>= 1): a sphere stops
  /// at the first of its farthest samples that no other sphere covers.
  int max_moves_per_sphere = 1 << 20;
};

/// For each sphere, worst error bound (radius - depth) first: while its
/// farthest member s (largest |s - c| + gap[s]) lies within another sphere k
/// with margin (|s - c_k| + gap[s] <= r_k) and accepts(k, s) holds, s moves
/// to k's members; then the radius is refitted exactly. A sphere keeps at
/// least one member. Radii never grow, so no error rises and every sample
/// stays covered with margin. `accepts` may be empty (every move allowed);
/// the builder uses it to keep a moved sample covered by the receiver's
/// ancestors. Members stay sorted. Returns the number of samples moved.
/// Deterministic.
int shrink_by_exchange(const ReductionProblem& problem, std::vector<FittedSphere>& spheres,
                       const ExchangeOptions& options = {},
                       const std::function<bool(int receiver, int sample)>& accepts = {});

}  // namespace icd::mesh
