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

/// Options of build_sphere_tree(): the tree's shape, then one group per
/// build stage in the order the stages run, then the budget. Lengths are
/// fractions of the longest side of the model's axis-aligned bounding box (so
/// 0.001 is 2 units when that side is 2000), which makes the defaults
/// independent of the model's scale. Figures quoted below are medians over
/// 7 builds of the mesh scaled by 1 + E (E ~ 1e-12: the build is sensitive
/// to rounding) unless said otherwise, in units of a longest side of 2000,
/// "mean42" / "worst42" the leaf level's mean / worst error on 42 probe
/// directions
/// (experiments/studies/spheretree/results/; switches that were removed:
/// HISTORY-options.md there).
struct SphereTreeOptions {
  /// Surface samples and the medial axis the spheres are placed on.
  struct Sampling {
    /// Spacing of the coverage samples (relative); their gap (<= spacing /
    /// sqrt(3) on well-shaped triangles) is the coverage margin every sphere
    /// adds.
    double cover_spacing = 1.0 / 550.0;
    /// Spacing of the samples whose Voronoi diagram gives the medial axis and
    /// on which the spheres are placed (relative, >= cover_spacing).
    double medial_spacing = 1.0 / 25.0;
    int refinement_iterations = 2;  ///< adaptive medial-axis rounds (>= 0)
    /// Medial sphere error that triggers refinement (relative).
    double refinement_tolerance = 0.002;
  };

  /// The reduction of a node's medial samples to its children: greedy
  /// splitting + Lloyd rounds (reduce_to_spheres), level by level.
  struct Reduction {
    int lloyd_iterations = 8;  ///< see ReductionOptions
    /// After the top-down pass, optimise the leaves jointly (a leaf may take
    /// samples of a neighbour of its parent) and refit the inner nodes
    /// bottom-up so that each still covers the union of its children's
    /// samples. With worst_share 1 and leaf_worst_target = leaf_worst_factor
    /// = 0 (SphereFit::shell) it gives a leaf shell thinner than the
    /// reference toolkit's (dragon: union volume outside the object per area
    /// 33 -> 23.4, the toolkit's 24.1) at a higher per-sphere mean (mean42 16.9 ->
    /// 19.5) and a thicker level 2; on the bunny it lowers both. Off: the
    /// default is tuned for the per-sphere mean.
    bool joint_leaf_refinement = false;
  };

  /// How each level's sphere cap is shared among the parents
  /// (allocate_children), and which parent each node ends under.
  struct Allocation {
    /// The first (1 - worst_share) of the spheres beyond one per parent go
    /// where the summed child error drops most (favours the mean error), the
    /// rest to the parents with the worst child (favours the worst error).
    /// In [0, 1]. Lower shares lower the dragon's leaf mean and raise its
    /// worst above 80 (0.1: mean42 -5 %, worst42 <= 80 in 2 of 7 builds).
    double worst_share = 0.2;
    /// When > 0 (relative, like the spacings): the leaf level's cap is shared
    /// by the threshold rule of allocate_children() instead of worst_share:
    /// first each parent the fewest children whose worst error bound (on the
    /// medial samples) is <= leaf_worst_target * longest side, then the rest
    /// where the summed bound drops most. Upper levels keep worst_share.
    /// 0 turns the rule off (with leaf_worst_factor 0 too). 0.045 with
    /// leaf_worst_factor 1.05 lowers the dragon's mean42 17.68 -> 16.88
    /// (worst42 <= 80 in 6 of 7 builds either way) and keeps the bunny's
    /// worst within its spread.
    double leaf_worst_target = 0.045;
    /// When > 0: the threshold rule's threshold at the leaf level is this
    /// factor times the largest worst bound of the configurations the fixed
    /// split (worst_share) would choose there (so it follows the model instead
    /// of its bounding box); the smaller of the two when leaf_worst_target > 0.
    /// 0: off.
    double leaf_worst_factor = 1.05;
    /// After the leaves are final, choose every node's parent anew, levels
    /// from the leaves up, to lower the sum of the parents' radii
    /// (regroup_children; no parent gets more than `branching` children):
    /// meant for joint_leaf_refinement, whose leaves have left the patches
    /// their parents were fitted to. The leaves are unchanged. With the shell
    /// settings (SphereFit::shell) a full traversal of two approaching copies
    /// (one build, 400 poses) tests 13 % (dragon) / 16 % (bunny) fewer sphere
    /// pairs; on the default tree no gain (+3 %), hence off.
    bool regroup_parents = false;
    /// Children a parent at level >= 1 may get while the tree is built (0:
    /// branching; else >= branching). Above branching, levels 2 and below are
    /// built as if their parents could take that many (so the allocation can
    /// give some parents more children and others fewer; a parent gets no
    /// more than it has coverage samples), and at the end each level is
    /// regrouped under the level above with at most `branching` children per
    /// node (regroup_children), leaves first: the leaves do not change, inner
    /// nodes are refitted and polished around their new children. The tree
    /// keeps its branching factor and caps. Off: for the per-sphere mean it
    /// measured worse than the default (dragon, 12: mean42 -8 %, but worst42
    /// <= 80 in 4 of 7 builds instead of 6, upper levels looser, most of the
    /// gain leaves that cover nothing alone). With 16 and the worst-first
    /// allocation (worst_share 1, leaf targets 0) one dragon build had the
    /// thinnest leaf shell measured (20.8 against 23.4 for the shell preset),
    /// at mean42 22.0; its upper levels and traversal cost were not measured.
    int build_branching = 0;
  };

  /// Boundary exchanges: samples handed to neighbouring spheres that cover
  /// them already (shrink_by_exchange, relieve_worst, lower_error_sum).
  struct Exchange {
    /// Rounds of boundary exchange among the children of each node, each
    /// followed by a centre polish (see shrink_by_exchange, polish_sphere; >= 0).
    int sibling_rounds = 2;
    /// After the top-down pass, let the leaves exchange boundary samples across
    /// parents too (a sample may move to a leaf of another parent when that
    /// leaf and all its ancestors already cover it; no radius grows); inner
    /// nodes are then refitted to the union of their children's samples.
    bool across_leaves = true;
    /// With across_leaves: at most this many single-sample moves that lower the
    /// worst leaf error bound (see relieve_worst; 0 disables, >= 0). A receiving
    /// leaf grows below the worst leaf error; its ancestors may grow, each within
    /// its level's worst error bound before the moves.
    int relieve_moves = 200000;
    /// Passes of lower_error_sum over the leaves after the exchanges, which
    /// lowers the mean leaf error bound: a leaf hands the cap of samples that
    /// sets its radius to neighbours that grow less than it shrinks, whose
    /// ancestors already cover them (0: off, >= 0).
    int sum_passes = 4;
    double sum_cap = 0.1;  ///< see SumExchangeOptions::cap_fraction
    /// A receiving leaf's error bound stays below this share of the worst leaf
    /// bound (> 0). Larger lets the mean drop more and the worst rise; with
    /// WorstSplit relieving the worst, 0.9 measured best (dragon: mean on
    /// 2562 directions 2 % below 0.8's, worst42 <= 80 in 6 of 7 builds either
    /// way; 1.0: 3 % below, but only 5 of 7).
    double sum_max_share = 0.9;
  };

  /// The protrusion polish of every node, after the exchanges (only
  /// WorstSplit and the regrouping come later).
  struct Polish {
    /// Every node, leaves first, moves its centre to lower its true error
    /// (how far its surface sticks out of the object, measured on points of
    /// the sphere's surface; see polish_protrusion), its radius the smallest
    /// that covers its samples with margin. Coverage is kept.
    bool enabled = true;
    /// Rounds in which the polished leaves hand boundary samples to
    /// neighbours that already cover them (and whose ancestors do;
    /// shrink_by_exchange), each followed by a new polish of the leaves that
    /// changed (>= 0).
    int exchange_rounds = 1;
    ProtrusionPolishOptions protrusion;  ///< see polish_protrusion
  };

  /// The last step that changes leaves (split_worst_leaves): those with the largest
  /// true error, measured on options.measure_directions (a set neither the
  /// polish nor the evaluation uses), are split in two, in the leaf slots the
  /// top-down pass lost, when both halves have a lower true error; near the
  /// worst (options.relief_fraction) even when the mean rises and, in a full
  /// parent, after merging two siblings; below it only when the mean does not
  /// rise. Coverage is kept; the true worst never rises.
  struct WorstSplit {
    /// On by default: the dragon's worst42 is <= 80 in 6 of 7 builds instead
    /// of 3 (median 80.2 -> 73.7), its mean unchanged within the spread, for
    /// about 10 s CPU.
    bool enabled = true;
    WorstSplitOptions options;  ///< see split_worst_leaves (its deadline is time_limit's)
  };

  int branching = 8;  ///< at most this many children per node (>= 2)
  /// Levels *below the root*: the tree has depth + 1 levels (the root is
  /// level 0), at most branching^l nodes on level l. depth 3 with branching 8
  /// is the paper's setting (1 + 8 + 64 + 512 nodes at most), as in the
  /// reference toolkit (whose .sph header then reads "4 8").
  int depth = 3;
  /// Optional cap on the number of spheres of each level (index = level; a
  /// missing or non-positive entry means branching^level). Extra spheres go
  /// where they lower the error most (see Allocation).
  std::vector<int> max_spheres_per_level;

  Sampling sampling;
  Reduction reduction;
  Allocation allocation;
  Exchange exchange;
  Polish polish;
  WorstSplit worst_split;

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
  int num_regrouped = 0;           ///< parent changes made by regroup_parents or build_branching
  WorstSplitResult worst_split;    ///< what split_worst_leaves did (with WorstSplit::enabled)
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
/// its children divide those samples. Deterministic for the same arrays, but
/// not independent of the order of vertices and faces (sums and ties round
/// differently: 420 against 505 leaves were seen for one geometry): callers
/// that need a tree of the geometry alone pass canonical_order(mesh)
/// (mesh/pipeline/canonical.hpp), as preprocess() does; the samples then
/// refer to that order. Throws ParameterError for invalid options,
/// InputError for an empty or invalid mesh.
SphereTreeBuild build_sphere_tree(const SurfaceMesh& mesh, const SphereTreeOptions& options = {});

}  // namespace icd::mesh
