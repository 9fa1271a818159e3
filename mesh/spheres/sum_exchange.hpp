#pragma once
/// Boundary exchange that lowers the summed (mean) error bound of a sphere
/// set: a sphere hands the cap of samples that sets its radius to neighbours
/// that need to grow less than it shrinks.
#include <functional>
#include <vector>

#include <icd/mesh/spheres/reduction.hpp>

namespace icd::mesh {

/// Options of lower_error_sum().
struct SumExchangeOptions {
  int passes = 2;  ///< passes over all spheres (>= 0); stops early when a pass moves nothing
  /// A sphere offers the members within this fraction of its error bound
  /// (radius - depth) of its radius (in (0, 1]).
  double cap_fraction = 0.1;
};

/// For each sphere A, largest error bound first: the cap of members s with
/// |s - c_A| + gap[s] > r_A - cap_fraction * error_A is offered; each goes to
/// the sphere overlapping A that needs to grow least to cover it with margin
/// (accepts(k, s) must hold; empty: always). The move is made when the
/// receivers' summed growth is smaller than A's radius drop (so the summed
/// error bound falls), A keeps at least one member and no receiver's error
/// bound exceeds `max_error`. Centres and depths are fixed; radii stay exact
/// covering radii of the members. Every sample stays covered with margin and
/// in exactly one sphere; members stay sorted. Returns the number of caps
/// moved. Deterministic. Throws ParameterError for invalid options.
int lower_error_sum(const ReductionProblem& problem, std::vector<FittedSphere>& spheres,
                    double max_error, const SumExchangeOptions& options = {},
                    const std::function<bool(int receiver, int sample)>& accepts = {});

}  // namespace icd::mesh
