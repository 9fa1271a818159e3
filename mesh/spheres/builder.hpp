#pragma once
/// Top-down construction of a wrapped sphere tree from an adaptive
/// medial-axis approximation (paper sec. 4.1; Bradshaw & O'Sullivan 2004).
#include <string>
#include <utility>
#include <vector>

#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/types.hpp>
#include <icd/mesh/spheres/exchange.hpp>
#include <icd/mesh/spheres/protrusion.hpp>
#include <icd/mesh/spheres/reduction.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>
#include <icd/mesh/spheres/worst_split.hpp>

namespace icd::mesh {

/// Options of build_sphere_tree(). Lengths are fractions of the longest side
/// of the model's axis-aligned bounding box (so 0.001 is 2 units when that
/// side is 2000), which makes the defaults independent of the model's scale.
struct SphereTreeOptions {
  int branching = 8;  ///< at most this many children per node (>= 2)
  /// Children a parent at level >= 1 may get while the tree is built (0:
  /// branching; else >= branching). Above branching, levels 2 and below are
  /// built as if their parents could take that many (so the allocation can
  /// give some parents more children and others fewer), and at the end each
  /// level is regrouped under the level above with at most `branching`
  /// children per node (regroup_children), leaves first: the leaves do not
  /// change, inner nodes are refitted and polished around their new
  /// children. The tree keeps its branching factor and caps. Measured with
  /// 12 and inner_worst_target 0.085 (7 perturbed builds, medians): dragon
  /// leaf mean42 16.88 -> 15.34 but worst42 <= 80 in 4 instead of 6 of 7,
  /// bunny mean42 14.45 -> 12.79; upper levels looser; hence off
  /// (experiments/spheretree/results/README.md, "This session (5)"). Most
  /// of that gain is leaves that cover nothing alone (about 170 instead of
  /// 110 on 4 dragon builds; LevelMetrics::num_redundant_spheres): the
  /// union's shell is 10 % thicker than the default's ("This session (6)").
  int build_branching = 0;
  /// Levels *below the root*: the tree has depth + 1 levels (the root is
  /// level 0), at most branching^l nodes on level l. depth 3 with branching 8
  /// is the paper's setting (1 + 8 + 64 + 512 nodes at most), as in the
  /// reference toolkit (whose .sph header then reads "4 8").
  int depth = 3;
  /// Optional cap on the number of spheres of each level (index = level; a
  /// missing or non-positive entry means branching^level). Extra spheres go
  /// where they lower the error most.
  std::vector<int> max_spheres_per_level;
  /// How a cap is shared: the first (1 - worst_share) of the spheres beyond
  /// one per parent go where the summed child error drops most (favours the
  /// mean error), the rest to the parents with the worst child (favours the
  /// worst error). In [0, 1].
  double worst_share = 0.2;
  /// When > 0 (relative, like the spacings): the leaf level's cap is shared
  /// by the threshold rule of allocate_children() instead of worst_share:
  /// first each parent the fewest children whose worst error bound (on the
  /// medial samples) is <= leaf_worst_target * longest side, then the rest
  /// where the summed bound drops most. Upper levels keep worst_share.
  /// 0 turns the rule off (with leaf_worst_factor 0 too). Default 0.045
  /// with leaf_worst_factor 1.05 (7 perturbed builds, medians: dragon mean42
  /// 17.68 -> 16.88, mean2562 20.83 -> 19.93, worst42 <= 80 in 6 of 7 either
  /// way; bunny mean42 14.62 -> 14.45, worst42 45.0 -> 49.4, all <= 80;
  /// experiments/spheretree/results/README.md).
  double leaf_worst_target = 0.045;
  /// When > 0: the threshold rule's threshold at the leaf level is this
  /// factor times the largest worst bound of the configurations the fixed
  /// split (worst_share) would choose there (so it follows the model instead
  /// of its bounding box); the smaller of the two when leaf_worst_target > 0.
  /// 0: off.
  double leaf_worst_factor = 1.05;
  /// Spacing of the coverage samples (relative); their gap (<= spacing /
  /// sqrt(3) on well-shaped triangles) is the coverage margin every sphere adds.
  double cover_spacing = 1.0 / 550.0;
  /// Spacing of the samples whose Voronoi diagram gives the medial axis and
  /// on which the spheres are placed (relative, >= cover_spacing).
  double medial_spacing = 1.0 / 25.0;
  int refinement_iterations = 2;        ///< adaptive medial-axis rounds (>= 0)
  double refinement_tolerance = 0.002;  ///< medial sphere error that triggers refinement (relative)
  int lloyd_iterations = 8;             ///< see ReductionOptions
  /// Rounds of boundary exchange among the children of each node, each
  /// followed by a centre polish (see shrink_by_exchange, polish_sphere; >= 0).
  int exchange_rounds = 2;
  /// After the top-down pass, let the leaves exchange boundary samples across
  /// parents too (a sample may move to a leaf of another parent when that
  /// leaf and all its ancestors already cover it; no radius grows); inner
  /// nodes are then refitted to the union of their children's samples.
  bool leaf_exchange = true;
  /// With leaf_exchange: at most this many single-sample moves that lower the
  /// worst leaf error bound (see relieve_worst; 0 disables, >= 0). A receiving
  /// leaf grows below the worst leaf error; its ancestors may grow, each within
  /// its level's worst error bound before the moves.
  int relieve_moves = 200000;
  /// After the top-down pass, optimise the leaves jointly (a leaf may take
  /// samples of a neighbour of its parent) and refit the inner nodes
  /// bottom-up so that each still covers the union of its children's samples.
  /// With worst_share 1 and leaf_worst_target = leaf_worst_factor = 0 it
  /// gives a leaf shell thinner than the reference toolkit's (7 perturbed
  /// dragon builds, medians: union volume outside per area 33 -> 23.4, the
  /// toolkit's 24.1; median reach beyond the surface 41 -> 23;
  /// worst42 <= 80 in 7 of 7) at a higher per-sphere mean (mean42 16.9 ->
  /// 19.5) and a thicker level 2; on the bunny it lowers both. Off because
  /// the default is tuned for the per-sphere mean (experiments/spheretree/
  /// results/README.md, "This session (10)").
  bool joint_leaf_refinement = false;
  /// After the leaves are final, choose every node's parent anew, levels
  /// from the leaves up, to lower the sum of the parents' radii (as
  /// build_branching's regrouping does, here with no parent over capacity):
  /// meant for joint_leaf_refinement, whose leaves have left the patches
  /// their parents were fitted to. The leaves are unchanged. Measured with
  /// the shell settings (joint, worst_share 1, leaf targets 0; E = 0, 400
  /// approach poses of contact_tightness): sphere tests of a full traversal
  /// -13 % (dragon) / -16 % (bunny), level-2 pairs 13.9 -> 10.8 (dragon);
  /// on the default tree no gain (tests +3 %), hence off.
  bool regroup_parents = false;
  /// Passes of lower_error_sum over the leaves after the exchanges, which
  /// lowers the mean leaf error bound: a leaf hands the cap of samples that
  /// sets its radius to neighbours that grow less than it shrinks, whose
  /// ancestors already cover them (0: off, >= 0).
  int sum_exchange_passes = 4;
  double sum_exchange_cap = 0.1;  ///< see SumExchangeOptions::cap_fraction
  /// A receiving leaf's error bound stays below this share of the worst leaf
  /// bound (> 0). Larger lets the mean drop more and the worst rise; with
  /// split_worst relieving the worst, 0.9 measured best (7 perturbed dragon
  /// builds: median mean2562 21.22 -> 20.83 against 0.8, worst42 <= 80 in 6
  /// of 7 either way; 1.0: 20.51 but only 5 of 7).
  double sum_exchange_max_share = 0.9;
  /// Last step: every node, leaves first, moves its centre to lower its true
  /// error (how far its surface sticks out of the object, measured on points
  /// of the sphere's surface; see polish_protrusion), its radius the smallest
  /// that covers its samples with margin. Coverage is kept.
  bool protrusion_polish = true;
  /// With protrusion_polish: rounds in which the polished leaves hand
  /// boundary samples to neighbours that already cover them (and whose
  /// ancestors do; shrink_by_exchange), each followed by a new polish of the
  /// leaves that changed (>= 0).
  int protrusion_exchange_rounds = 1;
  ProtrusionPolishOptions protrusion;  ///< see polish_protrusion
  /// Very last step (split_worst_leaves): the leaves with the largest true
  /// error, measured on worst_split.measure_directions (a set neither the
  /// polish nor the evaluation uses), are split in two, in the leaf slots the
  /// top-down pass lost, when both halves have a lower true error; near the
  /// worst (worst_split.relief_fraction) even when the mean rises and, in a
  /// full parent, after merging two siblings; below it only when the mean
  /// does not rise. Coverage is kept; the true worst never rises. On by
  /// default: over 7 perturbed dragon builds it took the leaf worst42 <= 80
  /// in 6 instead of 3 (median 80.2 -> 73.7) with the mean unchanged within
  /// the spread (median mean2562 21.07 -> 21.22), for about 10 s CPU.
  bool split_worst = true;
  WorstSplitOptions worst_split;  ///< see split_worst_leaves (its deadline is time_limit's)
  /// Worker threads (0: std::thread::hardware_concurrency(); 1: none). The
  /// per-node steps (each level's reduction and fitting of a parent's
  /// children, the leaf polish between boundary exchanges, the protrusion
  /// polish) run one node per task, split_worst_leaves one candidate
  /// division per task; the medial axis' inside tests and the root's
  /// reduction (one node) are split into blocks of samples or spheres.
  /// Serial: the Delaunay triangulation and the boundary exchanges across
  /// the leaf level (greedy, order-dependent). The tree does not depend on
  /// the number of threads (as long as the CPU budget below is not reached:
  /// it counts the CPU time of all threads).
  int threads = 0;
  /// Budget in CPU seconds of this process (clock_gettime(CLOCK_PROCESS_CPUTIME_ID),
  /// not wall-clock time, so a loaded machine does not change the tree; > 0).
  /// Past it the optimisation stops early (no more Lloyd rounds or polish
  /// steps); the tree stays valid and covering.
  double time_limit = 60.0;
};

/// Result of build_sphere_tree().
struct SphereTreeBuild {
  collision::SphereTree tree;  ///< spheres in model units; assoc_* left empty
  SurfaceSamples samples;      ///< the coverage samples
  /// Coverage samples of each node: node i covers samples node_samples[i]
  /// with margin (|s - c| + gap[s] <= r); its children divide them.
  std::vector<std::vector<int>> node_samples;
  std::vector<double> node_depth;  ///< distance from each centre to the surface
  int num_medial_spheres = 0;      ///< medial spheres (Voronoi + cover) after refinement
  int num_refinement_points = 0;   ///< points added by the adaptive refinement
  double seconds = 0;              ///< wall-clock build time
  double cpu_seconds = 0;          ///< process CPU time of the build
  double medial_seconds = 0;       ///< of which sampling + medial axis
  double polish_cpu_seconds = 0;   ///< CPU time of the protrusion polish
  int num_polished = 0;            ///< nodes whose centre the protrusion polish moved
  bool hit_time_limit = false;     ///< true when the optimisation was cut short
  int num_regrouped = 0;           ///< parent changes made by build_branching's regrouping
  WorstSplitResult worst_split;    ///< what split_worst_leaves did (with split_worst)
  /// For each level l >= 1 (index l - 1): the largest worst child error bound
  /// (medial samples, model units) of the configurations the allocation chose.
  std::vector<double> allocated_worst_bound;
  /// Process CPU seconds of each build step, in order (step name, seconds).
  std::vector<std::pair<std::string, double>> step_cpu_seconds;
  /// Wall-clock seconds of the same steps (how much the worker threads gain).
  std::vector<std::pair<std::string, double>> step_wall_seconds;
};

/// Builds the wrapped sphere tree of the triangle mesh (V #V x 3, F #F x 3,
/// outward-oriented; holes are closed first, see close_holes). Every level
/// covers the whole surface: each node covers its samples with margin, and
/// its children divide those samples. Deterministic. Throws ParameterError
/// for invalid options, InputError for an empty or invalid mesh.
SphereTreeBuild build_sphere_tree(const SurfaceMesh& mesh, const SphereTreeOptions& options = {});

}  // namespace icd::mesh
