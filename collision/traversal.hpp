#pragma once
/// Interruptible collision query between two sphere trees (paper 4.2, Fig. 7),
/// the depth-first baseline (Fig. 4) and a bounded-memory best-first mode.
#include <cstdint>
#include <limits>
#include <vector>

#include <icd/collision/sphere_tree.hpp>

namespace icd::collision {

/// A pair of nodes: `a` indexes the first tree, `b` the second.
struct NodePair {
  int32_t a = 0;
  int32_t b = 0;
  friend bool operator==(const NodePair&, const NodePair&) = default;
};

/// Order in which sphere pairs are refined.
enum class TraversalMode {
  /// Paper Fig. 7, fast path: FIFO PAIRLIST, level by level, pair order
  /// swapped; child pairs are tested as they are generated, so only
  /// overlapping pairs enter the list.
  BreadthFirstFifo,
  /// Paper Fig. 7 as printed: pairs are tested when popped (the list holds
  /// untested pairs); use with clock_check_interval 1 for the paper's clock
  /// read at every test (CollisionRequest::paper_reference).
  BreadthFirstLiteral,
  /// Paper Fig. 4: LIFO (recursive order), optionally depth-capped; child
  /// pairs tested as they are generated.
  DepthFirst,
  /// Paper Fig. 4 as printed: LIFO, pairs tested when popped.
  DepthFirstLiteral,
  /// Best-first (see PriorityKey) with a capped list; tests on push.
  Priority,
};

/// True for the modes that test pairs when they are popped (as printed in the paper).
constexpr bool is_literal(TraversalMode m) {
  return m == TraversalMode::BreadthFirstLiteral || m == TraversalMode::DepthFirstLiteral;
}

/// What the Priority mode refines first.
enum class PriorityKey {
  LargestSphere,  ///< the pair with the largest sphere, max(r_a, r_b): shrinks the suspected region
                  ///< fastest
  DeepestOverlap,  ///< the pair with the deepest overlap r_a + r_b - |c_a - c_b| (contact detail
                   ///< first)
};

/// Why the query stopped.
enum class StopReason {
  Completed,   ///< nothing left to refine (or only pairs held back by a cap)
  TimeBudget,  ///< budget_seconds spent
  TestBudget,  ///< budget_tests sphere tests done
};

/// Which clock enforces budget_seconds.
enum class ClockSource {
  SteadyClock,   ///< std::chrono::steady_clock (~20-25 ns per read here)
  CycleCounter,  ///< rdtsc, calibrated once against steady_clock (x86-64 only; else steady_clock)
};

/// What to do and how long to try (see collide()).
struct CollisionRequest {
  /// Wall-clock budget in seconds (> 0); infinity = no time limit.
  double budget_seconds = std::numeric_limits<double>::infinity();
  /// Budget in sphere-sphere tests (>= 0); -1 = no limit. Deterministic, for tests.
  int64_t budget_tests = -1;
  TraversalMode mode = TraversalMode::BreadthFirstFifo;
  /// Parent filter (not in the paper; ignored by the literal modes): when a
  /// node is split, the children of the pair's other node are also tested,
  /// once, against it, and later only those that overlap it are tested
  /// against its children. Conservative for surface contacts as the plain
  /// traversal is (a point where the surfaces touch lies in every ancestor
  /// of the two leaves covering it, so a child on its path overlaps the
  /// other side's node at every step); it prunes leaf pairs whose spheres
  /// overlap away from both parents, so it reports a subset of the plain
  /// traversal's pairs. Fewer pairs and, on wrapped trees, fewer tests
  /// (tests include the filter's own).
  bool parent_filter = false;
  /// Sphere tests between two clock reads (>= 1); the paper reads it at every test (1).
  int clock_check_interval = 16;
  ClockSource clock = ClockSource::SteadyClock;
  /// Nodes at this level or deeper are not split (treated as leaves; pairs
  /// stopped there are reported in `untested`). Default: no cap.
  int depth_cap = std::numeric_limits<int>::max();
  /// Priority mode: largest number of pairs held in the list (>= 8, and at
  /// least the largest child count, else one node's children overshoot it).
  /// When children would not fit, the lower-priority half of the list is
  /// moved, unrefined, to `untested` (the least valuable work is given up first).
  std::size_t max_list_size = 1 << 14;
  PriorityKey priority = PriorityKey::LargestSphere;
  /// Temporal coherence: if non-null, start from these pairs (normally the
  /// previous result's `front`) instead of the root pair. Conservative as long
  /// as the pairs form a cut of the pair tree, which `front` does.
  const std::vector<NodePair>* start_front = nullptr;
  /// Fill CollisionResult::front (costs one push per pruned pair).
  bool record_front = false;

  /// The paper's reference configuration: Fig. 7 literally, clock at every test.
  static CollisionRequest paper_reference(double budget_seconds);
};

/// Throws ParameterError naming the field when `request` is invalid:
/// budget_seconds <= 0 (infinity for none), budget_tests < -1,
/// clock_check_interval < 1, depth_cap < 0, Priority with max_list_size < 8.
void validate(const CollisionRequest& request);

/// What the query found. A point where the two (covered) surfaces touch lies
/// in both spheres of some pair of `colliding` or `untested`.
struct CollisionResult {
  std::vector<NodePair> colliding;  ///< COLLISIONLIST: overlapping leaf pairs
  /// Pairs not refined to leaves, assumed colliding: PAIRLIST at interruption
  /// (in the fast path these were found overlapping but not yet split; in the
  /// literal mode they are untested), the children pairs of a node whose
  /// children were being tested one by one when the budget ran out (not
  /// tested: they need not overlap), plus pairs held back by depth_cap or
  /// max_list_size.
  std::vector<NodePair> untested;
  /// If requested: a cut of the pair tree (pruned pairs + colliding + untested)
  /// to seed the next frame's query.
  std::vector<NodePair> front;
  bool interrupted = false;  ///< stopped by a budget with work left
  StopReason stop_reason = StopReason::Completed;
  int64_t tests = 0;   ///< sphere-sphere overlap tests done
  double seconds = 0;  ///< wall time used (steady_clock)
  /// Deepest level L such that every reported pair is made of spheres at
  /// level >= L or of leaves (the tightness the answer reached).
  int completed_level = 0;
  std::size_t peak_list_size = 0;  ///< largest PAIRLIST / stack / heap size seen
};

/// Collides sphere tree `a` with sphere tree `b` (current spheres) under the
/// request's budget. Pairs are pruned when their spheres do not overlap, which
/// is conservative for surface contacts when each node covers its subtree's
/// surface patch (wrapped trees, octree trees). Reuses `result`'s storage.
/// Time budget: the clock is read every clock_check_interval tests; the time
/// needed to copy the pending pairs into `untested` is reserved out of the
/// budget, so the call returns close to the deadline (reuse `result` between
/// queries so that its vectors do not reallocate). The first timed query of a
/// process calibrates its clocks (~20 ms) before its budget starts.
/// Throws ParameterError for an invalid request (see validate(); also a
/// start_front index out of range). Trees are assumed valid (see validate()).
void collide(const SphereTree& a, const SphereTree& b, const CollisionRequest& request,
             CollisionResult& result);

/// Convenience overload returning a fresh result.
CollisionResult collide(const SphereTree& a, const SphereTree& b, const CollisionRequest& request);

/// The cost per pending pair of finishing an interrupted timed query (copying
/// the pairs out), s, that this thread's next timed query reserves out of its
/// budget: learnt from this thread's interrupted queries (0 before its first
/// timed query). For studies of the budget's accuracy.
double finish_cost_per_pair();
/// The calibrated copy cost per pair, s (the floor of the learnt one).
double calibrated_finish_cost_per_pair();

}  // namespace icd::collision
