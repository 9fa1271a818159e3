#pragma once
/// How a level's sphere cap is shared among its parents: the number of
/// children each parent gets (one of its precomputed configurations).
#include <vector>

namespace icd::mesh {

/// What each child count would cost one parent: for k = 1 .. worst.size()
/// children (index k - 1), the largest and the summed error bound of the
/// children (model units, >= 0). worst and sum have the same, non-zero size.
struct ChildCountCosts {
  std::vector<double> worst;  ///< worst[k - 1]: the largest child error bound with k children
  std::vector<double> sum;    ///< sum[k - 1]: the summed child error bound with k children
};

/// Options of allocate_children().
struct AllocationOptions {
  /// Fixed split (used when worst_threshold <= 0): of the spheres beyond one
  /// per parent, the first (1 - worst_share) go one at a time where the summed
  /// error drops most, the rest to the parent with the largest worst child
  /// error. In [0, 1].
  double worst_share = 0.2;
  /// Constrained rule when > 0 (model units): first every parent gets the
  /// fewest children whose worst child bound is <= worst_threshold (the
  /// parents with the largest worst bound served first while the cap lasts),
  /// then the remaining spheres go where the summed error drops most per
  /// sphere spent, a parent moving from k to the fewest k' > k children whose
  /// worst bound stays <= max(worst_threshold, its worst bound with k) (never
  /// to a k' above that: spheres no parent can take that way stay unspent).
  double worst_threshold = 0;
};

/// The number of children of each parent (result[p] in [1, costs[p].worst.size()])
/// when the level may hold at most `cap` spheres: one each, then the extra
/// spheres by the rule of `options` (see AllocationOptions). The counts sum
/// to min(max(cap, #parents), sum of the configuration sizes) with the fixed
/// split, to at most that with the threshold rule. With
/// worst_threshold > 0, if the cap allows every parent its fewest children
/// with worst bound <= worst_threshold (the parents for which some k has),
/// every such parent ends with worst bound <= worst_threshold. Deterministic
/// (ties go to the higher parent index). Throws ParameterError for empty or
/// mismatched cost lists, negative costs or options out of range.
std::vector<int> allocate_children(const std::vector<ChildCountCosts>& costs, long long cap,
                                   const AllocationOptions& options);

}  // namespace icd::mesh
