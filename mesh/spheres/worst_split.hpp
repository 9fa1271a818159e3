#pragma once
/// Spends the leaf budget the top-down pass leaves unused on the leaves with
/// the largest *true* error (how far the sphere sticks out of the object,
/// measured on many directions; issue 5): the worst leaf is split in two
/// while its parent has room and the split lowers its true error.
#include <vector>

#include <icd/mesh/spheres/cpu_clock.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/protrusion.hpp>
#include <icd/mesh/spheres/reduction.hpp>

namespace icd::mesh {

/// The leaf level of a sphere tree as split_worst_leaves() edits it.
/// Leaves of one parent are contiguous and in parent order (the breadth-first
/// layout); all three vectors have one entry per leaf.
struct LeafLevel {
  std::vector<FittedSphere> spheres;     ///< members = coverage (dense) samples
  std::vector<std::vector<int>> medial;  ///< medial (coarse) samples of each leaf
  std::vector<int> parent;               ///< index of each leaf's parent on the level above
};

/// Options of split_worst_leaves().
struct WorstSplitOptions {
  /// Spiral directions (spiral_directions) on which the true error is
  /// measured to rank the leaves and accept a split (>= 1). 1000 is a set
  /// that neither the protrusion polish (128 / 600) nor the evaluation
  /// (icosahedral 42 / 162 / 2562) uses.
  int measure_directions = 1000;
  /// Spiral directions on which the candidate divisions of a leaf are
  /// compared (>= 1; cheaper than measure_directions).
  int choice_directions = 300;
  /// Leaves tried at most (>= 0); each try costs three candidate divisions,
  /// each with two centre fits and two protrusion polishes (about 0.15 s
  /// CPU on the dragon).
  int max_tries = 60;
  /// The relief band: leaves whose true error is at least this fraction of
  /// the level's worst at the start are split even when that raises the
  /// mean, and one without a free slot (its parent full or the level at its
  /// cap) gets one by merging two of its siblings into one sphere, when that
  /// sphere's true error is below the leaf's too (>= 0; above 1: no band).
  double relief_fraction = 0.85;
  /// Below the relief band a split is kept only when it raises the summed
  /// true error by at most this multiple of the level's mean true error at
  /// the start (measured on choice_directions), so that with the default 1
  /// the level's mean error does not rise with its sphere count (>= 0).
  double mean_rise_limit = 1.0;
  ProtrusionPolishOptions polish;  ///< polish of the two halves (see polish_protrusion)
  /// Past this process CPU time no more leaf is tried (the level stays valid).
  CpuClock::time_point deadline = CpuClock::time_point::max();
};

/// What split_worst_leaves() did.
struct WorstSplitResult {
  int splits = 0;             ///< leaves replaced by two
  int tries = 0;              ///< leaves for which a split was computed
  int measured = 0;           ///< spheres whose true error was measured
  double worst_before = 0;    ///< largest true error of the level at the start (model units)
  double worst_after = 0;     ///< and at the end (<= worst_before)
  double mean_before = 0;     ///< mean true error of the level at the start, on choice_directions
  int blocked_by_parent = 0;  ///< times the worst remaining leaf's parent was full
  int merges = 0;             ///< sibling pairs merged to make room for a split
  /// Tries in the relief band that failed because a half's true error was not
  /// below the leaf's (or the leaf did not divide in two)...
  int relief_no_split = 0;
  /// ... and because its parent (or the level) was full and no merge of two
  /// siblings gave a sphere below the leaf's true error.
  int relief_no_merge = 0;
};

/// Repeatedly, the leaf with the largest true error E (sphere_protrusion on
/// options.measure_directions, found lazily: the error bound radius - depth
/// is an upper bound of it, so only leaves whose bound exceeds the largest
/// true error found are measured) is split in two. Candidate divisions: the
/// two-sphere reduction of its medial samples (reduce_to_spheres) and the
/// median planes of its coverage samples across its two principal axes of
/// largest spread; each is
/// settled (assign_and_refit, polish_sphere, shrink_by_exchange) and both
/// centres moved by polish_protrusion; the one whose larger true error on
/// choice_directions is smallest is kept. The split uses a free slot when
/// the level holds fewer than `cap` leaves and the parent fewer than
/// `branching` children. It is made only when both halves' true errors are
/// below E and, unless E >= relief_fraction times the starting worst (the
/// relief band), their sum is below E + mean_rise_limit times the level's
/// mean true error at the start (on choice_directions). A leaf of the
/// relief band without a free slot makes room by merging the two
/// overlapping siblings whose union fits the sphere of lowest error bound
/// (fit_sphere on their samples, polish_sphere, polish_protrusion), when
/// that sphere's true error is below E as well (the leaf count is then
/// unchanged). A leaf is tried once (again after a
/// split). Stops after max_tries leaves, past the deadline, or when the level
/// is at its cap and no untried leaf is in the relief band. Every change
/// replaces spheres by ones of lower true error than E, so the level's true
/// worst error (on these directions) never rises.
/// The halves divide the leaf's samples, so every ancestor still covers them
/// and every level still covers the surface; the new leaf is inserted right
/// after the old one (siblings stay contiguous). Deterministic: `oracles`
/// holds one oracle of the same closed mesh per worker thread (a leaf's
/// candidate divisions and the starting errors are computed in parallel),
/// and the result does not depend on how many there are.
/// Preconditions: `coarse` and `dense` share the medial set; each leaf's
/// members are sorted, non-empty and covered with margin. Throws
/// ParameterError for invalid options, cap < 0, branching < 2, or no (or a
/// null) oracle.
WorstSplitResult split_worst_leaves(const ReductionProblem& coarse, const ReductionProblem& dense,
                                    const std::vector<const MeshOracle*>& oracles,
                                    const ReductionOptions& reduction, LeafLevel& level, int cap,
                                    int branching, const WorstSplitOptions& options = {});

}  // namespace icd::mesh
