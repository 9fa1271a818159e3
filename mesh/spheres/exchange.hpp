#pragma once
/// Boundary-sample exchange between neighbouring spheres: a sphere hands the
/// samples that set its radius to a neighbour that already covers them, then
/// shrinks. Lowers errors without raising any (sphere-tree refinement step).
#include <functional>
#include <vector>

#include <icd/mesh/spheres/reduction.hpp>

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

/// Lowers the worst error bound of a sphere set: repeatedly, the sphere with
/// the largest error bound hands its farthest member s to the sphere k that
/// would then have the smallest error bound max(r_k, |s - c_k| + gap[s]) -
/// depth_k, provided that is below the worst sphere's current error bound and
/// accepts(k, s) holds (empty: always); k grows to cover s. Stops when the
/// worst sphere cannot give its farthest member away, or after
/// `max_moves` moves. Only the worst error is guaranteed not to rise (others
/// may grow, below it); every sample stays covered with margin and in
/// exactly one sphere. A sphere keeps at least one member. Returns the number
/// of moves. Deterministic. Throws ParameterError for max_moves < 0.
int relieve_worst(const ReductionProblem& problem, std::vector<FittedSphere>& spheres,
                  int max_moves, const std::function<bool(int receiver, int sample)>& accepts = {});

}  // namespace icd::mesh
