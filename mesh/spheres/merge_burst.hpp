#pragma once
/// Merge/burst reduction of a medial-sphere set to a few spheres covering a
/// patch of surface samples (Bradshaw & O'Sullivan 2004, sec. 4: start from
/// the medial spheres that touch the samples, then repeatedly merge two
/// neighbouring spheres or burst one into its neighbours, whichever operation
/// leaves the lowest error).
#include <vector>

#include <icd/mesh/spheres/reduction.hpp>

namespace icd::mesh {

/// Options of merge_burst_reduce().
struct MergeBurstOptions {
  /// Two spheres are neighbours when one has a sample within this distance of
  /// a sample of the other (model units, > 0; about 1.5 sample spacings).
  double neighbour_radius = 1.0;
  int merge_candidates =
      192;                  ///< candidate centres tried per merge evaluation (evenly thinned, >= 1)
  bool allow_burst = true;  ///< consider bursts besides merges
  /// Lloyd rounds (see refine_jointly) run on each reduced configuration.
  int lloyd_iterations = 4;
};

/// For every sample s of problem.points, the medial sphere minimizing
/// |s - c| - depth among those with centre within `search_radius` of s (the
/// nearest centre when none is): the medial sphere that touches s best.
/// Returns #S indices into problem.medial. Throws ParameterError for a
/// non-positive radius.
std::vector<int> medial_owners(const ReductionProblem& problem, double search_radius);

/// Reduces the medial spheres owning `members` (owners from medial_owners)
/// to k = 1 .. max_k spheres covering `members` with margin. Each operation
/// is the merge of two neighbouring spheres (the merged sphere is the
/// candidate centre among the node's initial medial centres with the smallest
/// error bound radius - depth) or the burst of one sphere (its samples go to
/// the neighbour whose error bound grows least); the one whose resulting
/// error bound is lowest is applied. The configuration met at each count
/// k <= max_k is then improved by Lloyd rounds (refine_jointly). Returns
/// result[k - 1] = at most k spheres, each sample of `members` in exactly one
/// sphere's members. Deterministic. Throws ParameterError for max_k < 1,
/// empty members or bad options.
std::vector<std::vector<FittedSphere>> merge_burst_reduce(const ReductionProblem& problem,
                                                          const std::vector<int>& owners,
                                                          const std::vector<int>& members,
                                                          int max_k,
                                                          const ReductionOptions& reduction,
                                                          const MergeBurstOptions& options);

}  // namespace icd::mesh
