#include <icd/mesh/spheres/builder.hpp>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <memory>
#include <numeric>
#include <queue>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/allocation.hpp>
#include <icd/mesh/spheres/medial_axis.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/parallel.hpp>
#include <icd/mesh/spheres/point_grid.hpp>
#include <icd/mesh/spheres/regroup.hpp>
#include <icd/mesh/spheres/sort_indices.hpp>
#include <icd/mesh/spheres/sum_exchange.hpp>

namespace icd::mesh {
namespace {

using Clock = std::chrono::steady_clock;

void check_options(const SphereTreeOptions& o) {
  auto fail = [](const std::string& what) { throw ParameterError("SphereTreeOptions::" + what); };
  if (o.branching < 2) fail("branching must be >= 2, got " + std::to_string(o.branching));
  if (o.allocation.build_branching != 0 && o.allocation.build_branching < o.branching) {
    fail("allocation.build_branching must be 0 or >= branching, got " +
         std::to_string(o.allocation.build_branching));
  }
  if (o.depth < 0 || o.depth > 8) fail("depth must be in [0, 8], got " + std::to_string(o.depth));
  const auto& sampling = o.sampling;
  if (!(sampling.cover_spacing > 0) || !(sampling.medial_spacing >= sampling.cover_spacing)) {
    fail("sampling: cover_spacing must be > 0 and medial_spacing >= cover_spacing");
  }
  if (sampling.refinement_iterations < 0) fail("sampling.refinement_iterations must be >= 0");
  if (!(sampling.refinement_tolerance > 0)) fail("sampling.refinement_tolerance must be > 0");
  if (o.reduction.lloyd_iterations < 0) fail("reduction.lloyd_iterations must be >= 0");
  const auto& exchange = o.exchange;
  if (exchange.sibling_rounds < 0) fail("exchange.sibling_rounds must be >= 0");
  if (exchange.relieve_moves < 0) fail("exchange.relieve_moves must be >= 0");
  if (exchange.sum_passes < 0 || !(exchange.sum_cap > 0 && exchange.sum_cap <= 1) ||
      !(exchange.sum_max_share > 0)) {
    fail("exchange: sum_passes must be >= 0, sum_cap in (0, 1], sum_max_share > 0");
  }
  const auto& allocation = o.allocation;
  if (!(allocation.worst_share >= 0 && allocation.worst_share <= 1))
    fail("allocation.worst_share must be in [0, 1]");
  if (!(allocation.leaf_worst_target >= 0) || !(allocation.leaf_worst_factor >= 0))
    fail("allocation: leaf_worst_target and leaf_worst_factor must be >= 0");
  const WorstSplitOptions& split = o.worst_split.options;
  if (split.measure_directions < 1 || split.choice_directions < 1 || split.max_tries < 0 ||
      !(split.relief_fraction >= 0) || !(split.mean_rise_limit >= 0)) {
    fail(
        "worst_split.options: measure/choice directions must be >= 1, max_tries >= 0, "
        "relief_fraction >= 0");
  }
  if (!(o.time_limit > 0)) fail("time_limit must be > 0 seconds");
  if (o.threads < 0) fail("threads must be >= 0, got " + std::to_string(o.threads));
  const ProtrusionPolishOptions& protrusion = o.polish.protrusion;
  if (o.polish.exchange_rounds < 0) fail("polish.exchange_rounds must be >= 0");
  if (protrusion.search_directions < 1 || protrusion.check_directions < 1 ||
      protrusion.max_evaluations < 0 || !(protrusion.initial_step > 0) ||
      !(protrusion.min_step > 0)) {
    fail("polish.protrusion: search/check directions must be >= 1, evaluations >= 0, steps > 0");
  }
}

/// A node under construction: its sphere and its samples (coverage and medial).
struct Node {
  FittedSphere sphere;      // members = coverage samples
  std::vector<int> medial;  // medial (coarse) samples
};

/// The children a parent gets for each child count k (configs[k - 1]).
struct ParentChoices {
  std::vector<std::vector<FittedSphere>> configs;  // on the medial samples
  static double total_error(const std::vector<FittedSphere>& c) {
    double sum = 0;
    for (const auto& s : c) sum += s.error;
    return sum;
  }
  static double worst_error(const std::vector<FittedSphere>& c) {
    double worst = 0;
    for (const auto& s : c) worst = std::max(worst, s.error);
    return worst;
  }
};

/// The sphere cap of level l: branching^l, lowered by max_spheres_per_level[l] when positive.
long long level_cap(const SphereTreeOptions& options, int l) {
  long long cap = 1;
  for (int i = 0; i < l; ++i) cap = std::min<long long>(cap * options.branching, 1LL << 30);
  if (static_cast<int>(options.max_spheres_per_level.size()) > l &&
      options.max_spheres_per_level[static_cast<size_t>(l)] > 0) {
    cap = std::min<long long>(cap, options.max_spheres_per_level[static_cast<size_t>(l)]);
  }
  return cap;
}

/// True when every ancestor of leaf `leaf` (of the last level) covers sample
/// s with margin: the condition for moving s to that leaf without growing
/// any inner node.
bool ancestors_cover(const ReductionProblem& dense, const std::vector<std::vector<Node>>& levels,
                     const std::vector<std::vector<int>>& parent_of, int leaf, int s) {
  int node = leaf;
  for (size_t l = levels.size() - 1; l >= 1; --l) {
    node = parent_of[l][static_cast<size_t>(node)];
    const FittedSphere& a = levels[l - 1][static_cast<size_t>(node)].sphere;
    if (dense.reach(s, a) > a.radius) return false;
  }
  return true;
}

/// For each node of level l - 1 (l >= 1): the members of its children on
/// level l, joined and sorted (duplicates kept: children_divide_samples
/// looks for them).
std::vector<std::vector<int>> children_members(const std::vector<std::vector<Node>>& levels,
                                               const std::vector<std::vector<int>>& parent_of,
                                               size_t l) {
  std::vector<std::vector<int>> unions(levels[l - 1].size());
  for (size_t i = 0; i < levels[l].size(); ++i) {
    const auto& m = levels[l][i].sphere.members;
    auto& u = unions[static_cast<size_t>(parent_of[l][i])];
    u.insert(u.end(), m.begin(), m.end());
  }
  for (auto& u : unions) sort_indices(u);
  return unions;
}

/// True when the children of every inner node divide its coverage samples:
/// each sample of a node is a member of exactly one of its children, and the
/// children hold no other sample (the invariant the later steps rely on).
[[maybe_unused]] bool children_divide_samples(const std::vector<std::vector<Node>>& levels,
                                              const std::vector<std::vector<int>>& parent_of) {
  for (size_t l = 1; l < levels.size(); ++l) {
    const std::vector<std::vector<int>> unions = children_members(levels, parent_of, l);
    for (size_t p = 0; p < unions.size(); ++p) {
      std::vector<int> own = levels[l - 1][p].sphere.members;
      std::sort(own.begin(), own.end());
      if (unions[p] != own) return false;  // a duplicate, a missing or a foreign sample
    }
  }
  return true;
}

/// Removes the nodes of level `l` whose `keep` entry is 0 (they must have no
/// children), keeping the order of the others, and renumbers the parent
/// indices of level l + 1.
void remove_nodes(std::vector<std::vector<Node>>& levels, std::vector<std::vector<int>>& parent_of,
                  size_t l, const std::vector<char>& keep) {
  assert(keep.size() == levels[l].size());
  if (std::all_of(keep.begin(), keep.end(), [](char k) { return k != 0; })) return;
  std::vector<int> renumber(keep.size(), -1);
  std::vector<Node> nodes;
  std::vector<int> parents;
  for (size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    renumber[i] = static_cast<int>(nodes.size());
    nodes.push_back(std::move(levels[l][i]));
    if (l >= 1) parents.push_back(parent_of[l][i]);
  }
  levels[l] = std::move(nodes);
  if (l >= 1) parent_of[l] = std::move(parents);
  if (l + 1 < levels.size()) {
    for (int& p : parent_of[l + 1]) {
      assert(renumber[static_cast<size_t>(p)] >= 0 && "a removed node had children");
      p = renumber[static_cast<size_t>(p)];
    }
  }
}

/// Jointly re-optimises the leaf level across sibling groups (a leaf may take
/// samples from a neighbour of its parent), then restores the wrapped-tree
/// invariant bottom-up: each inner node's samples become the union of its
/// children's, and its sphere is re-centred and refitted to cover them. A
/// leaf left without samples is removed (an inner node left without children
/// too), so that the children still divide their parent's samples.
void refine_leaves(const ReductionProblem& coarse, const ReductionProblem& dense,
                   const MeshOracle& oracle, const SurfaceSamples& dense_samples, const MatX3i& F,
                   const ReductionOptions& reduction, std::vector<std::vector<Node>>& levels,
                   std::vector<std::vector<int>>& parent_of) {
  std::vector<Node>& leaves = levels.back();
  std::vector<FittedSphere> spheres;
  for (size_t i = 0; i < leaves.size(); ++i) {
    FittedSphere s = leaves[i].sphere;
    s.members = leaves[i].medial;
    spheres.push_back(std::move(s));
  }
  refine_jointly(coarse, spheres, reduction);
  std::vector<std::vector<int>> medial(spheres.size());  // the new medial members
  for (size_t j = 0; j < spheres.size(); ++j) medial[j] = spheres[j].members;

  // Dense samples go to the best sphere among their current leaf and the
  // owners of the coarse samples at their triangle's corners (the first #V
  // coarse samples are the mesh vertices).
  std::vector<int> coarse_owner(static_cast<size_t>(coarse.points.rows()), -1);
  for (size_t j = 0; j < spheres.size(); ++j) {
    for (int m : spheres[j].members) coarse_owner[static_cast<size_t>(m)] = static_cast<int>(j);
  }
  std::vector<int> dense_owner(static_cast<size_t>(dense.points.rows()), -1);
  for (size_t i = 0; i < leaves.size(); ++i) {
    for (int s : leaves[i].sphere.members)
      dense_owner[static_cast<size_t>(s)] = static_cast<int>(i);
  }
  auto reassign = [&]() {
    for (auto& sp : spheres) sp.members.clear();
    for (size_t s = 0; s < dense_owner.size(); ++s) {
      int best = dense_owner[s];
      if (best < 0) continue;
      const Eigen::Vector3d p = dense.points.row(static_cast<Eigen::Index>(s));
      auto cost = [&](int j) {
        return (p - spheres[static_cast<size_t>(j)].center).norm() -
               spheres[static_cast<size_t>(j)].depth;
      };
      double best_cost = cost(best);
      const int tri = dense_samples.face[static_cast<Eigen::Index>(s)];
      for (int k = 0; k < 3 && tri >= 0; ++k) {
        const int v = F(tri, k);
        const int j =
            v < static_cast<int>(coarse_owner.size()) ? coarse_owner[static_cast<size_t>(v)] : -1;
        if (j < 0) continue;
        const double c = cost(j);
        if (c < best_cost) best_cost = c, best = j;
      }
      dense_owner[s] = best;
      spheres[static_cast<size_t>(best)].members.push_back(static_cast<int>(s));
    }
  };
  reassign();
  for (auto& sp : spheres) {
    if (!sp.members.empty()) polish_sphere(dense, oracle, sp);
  }
  reassign();
  // Every dense sample now has exactly one leaf. A leaf left with none is
  // dropped (its slot is free for split_worst_leaves), so that the leaves
  // still divide the samples.
  std::vector<char> keep(leaves.size(), 1);
  for (size_t i = 0; i < leaves.size(); ++i) {
    FittedSphere& sp = spheres[i];
    if (sp.members.empty()) {
      keep[i] = 0;
      continue;
    }
    double r = 0;
    for (int m : sp.members) r = std::max(r, dense.reach(m, sp));
    sp.radius = r;
    sp.error = r - sp.depth;
    leaves[i].sphere = std::move(sp);
    if (!medial[i].empty()) leaves[i].medial = std::move(medial[i]);  // else keep it placeable
  }
  remove_nodes(levels, parent_of, levels.size() - 1, keep);
  // Bottom-up: inner nodes cover the union of their children's samples; one
  // whose children were all dropped is dropped too.
  for (size_t l = levels.size() - 1; l >= 1; --l) {
    std::vector<Node>& parents = levels[l - 1];
    std::vector<std::vector<int>> unions = children_members(levels, parent_of, l);
    std::vector<char> kept(parents.size(), 1);
    for (size_t p = 0; p < parents.size(); ++p) {
      if (unions[p].empty()) {
        kept[p] = 0;
        continue;
      }
      parents[p].sphere.members = std::move(unions[p]);
      polish_sphere(dense, oracle, parents[p].sphere);
    }
    remove_nodes(levels, parent_of, l - 1, kept);
  }
}

/// Samples of each inner node := union of its children's, radius refitted
/// exactly around the fixed centre (a sample moved by shrink_by_exchange was
/// covered by every ancestor of its receiver, so no radius grows; after
/// relieve_worst an ancestor grows within its level's worst error).
void refit_inner_nodes(const ReductionProblem& dense, std::vector<std::vector<Node>>& levels,
                       const std::vector<std::vector<int>>& parent_of) {
  for (size_t l = levels.size() - 1; l >= 1; --l) {
    std::vector<std::vector<int>> unions = children_members(levels, parent_of, l);
    for (size_t p = 0; p < unions.size(); ++p) {
      FittedSphere& sp = levels[l - 1][p].sphere;
      sp.members = std::move(unions[p]);
      double r = 0;
      for (int s : sp.members) r = std::max(r, dense.reach(s, sp));
      sp.radius = r;
      sp.error = r - sp.depth;
    }
  }
}

/// Boundary exchange across the whole leaf level: a sample may move to a leaf
/// whose ancestors all cover it with margin (shrink_by_exchange), or, to lower
/// the worst leaf error (relieve_worst), whose ancestors would stay within
/// their level's worst error bound when grown to cover it. Then every inner
/// node's samples become the union of its children's and its radius is
/// refitted exactly.
void exchange_across_leaves(const ReductionProblem& dense,
                            const std::vector<const MeshOracle*>& oracles,
                            std::vector<std::vector<Node>>& levels,
                            const std::vector<std::vector<int>>& parent_of, int rounds,
                            int relieve_moves) {
  const size_t last = levels.size() - 1;
  std::vector<FittedSphere> leaves;
  for (const Node& n : levels[last]) leaves.push_back(n.sphere);
  std::vector<double> level_worst(levels.size(), 0.0);
  for (size_t l = 0; l < levels.size(); ++l) {
    for (const Node& n : levels[l]) level_worst[l] = std::max(level_worst[l], n.sphere.error);
  }
  auto accepts = [&](int leaf, int s) {
    return ancestors_cover(dense, levels, parent_of, leaf, s);
  };
  auto accepts_growing = [&](int leaf, int s) {
    int node = leaf;
    for (size_t l = last; l >= 1; --l) {
      node = parent_of[l][static_cast<size_t>(node)];
      const FittedSphere& a = levels[l - 1][static_cast<size_t>(node)].sphere;
      const double r = dense.reach(s, a);
      if (r > a.radius && r - a.depth > level_worst[l - 1]) return false;
    }
    return true;
  };
  ExchangeOptions exchange;
  exchange.rounds = rounds;
  shrink_by_exchange(dense, leaves, exchange, accepts);
  if (relieve_moves > 0) {
    relieve_worst(dense, leaves, relieve_moves, accepts_growing);
    parallel_for(leaves.size(), static_cast<int>(oracles.size()), [&](size_t i, int worker) {
      polish_sphere(dense, *oracles[static_cast<size_t>(worker)], leaves[i]);
    });
    shrink_by_exchange(dense, leaves, exchange, accepts);
    relieve_worst(dense, leaves, relieve_moves, accepts_growing);
    shrink_by_exchange(dense, leaves, exchange, accepts);
  }
  for (size_t i = 0; i < leaves.size(); ++i) levels[last][i].sphere = std::move(leaves[i]);
  // Radii grow only within each level's worst error (accepts_growing).
  refit_inner_nodes(dense, levels, parent_of);
}

/// The protrusion polish of every node (polish_protrusion), leaves first;
/// then `exchange_rounds` times the leaves hand boundary samples to
/// neighbours whose ancestors all cover them (shrink_by_exchange) and the
/// leaves that changed are polished again. Returns the number of moves kept.
int polish_tree(const ReductionProblem& dense, const std::vector<const MeshOracle*>& oracles,
                std::vector<std::vector<Node>>& levels,
                const std::vector<std::vector<int>>& parent_of,
                const ProtrusionPolishOptions& options, int exchange_rounds,
                CpuClock::time_point deadline, bool inner = true) {
  int moved = 0;
  const size_t last = levels.size() - 1;
  // Each node's polish reads only its own sphere and samples: one task per node.
  auto polish_level = [&](size_t l, const std::vector<char>* only) {
    std::vector<char> did_move(levels[l].size(), 0);
    parallel_for(levels[l].size(), static_cast<int>(oracles.size()), [&](size_t i, int worker) {
      if ((only != nullptr && !(*only)[i]) || !(CpuClock::now() < deadline)) return;
      const auto seed = static_cast<unsigned>(1000003 * l + i);
      did_move[i] = polish_protrusion(dense, *oracles[static_cast<size_t>(worker)],
                                      levels[l][i].sphere, seed, options)
                            .moved
                        ? 1
                        : 0;
    });
    moved += static_cast<int>(std::count(did_move.begin(), did_move.end(), 1));
  };
  polish_level(last, nullptr);
  for (int round = 0; round < exchange_rounds && last >= 1; ++round) {
    auto accepts = [&](int leaf, int s) {
      return ancestors_cover(dense, levels, parent_of, leaf, s);
    };
    std::vector<FittedSphere> leaves;
    for (const Node& n : levels[last]) leaves.push_back(n.sphere);
    ExchangeOptions exchange;
    exchange.rounds = 2;
    if (shrink_by_exchange(dense, leaves, exchange, accepts) == 0) break;
    std::vector<char> changed(leaves.size(), 0);
    for (size_t i = 0; i < leaves.size(); ++i) {
      changed[i] = leaves[i].members != levels[last][i].sphere.members ? 1 : 0;
      levels[last][i].sphere = std::move(leaves[i]);
    }
    refit_inner_nodes(dense, levels, parent_of);
    polish_level(last, &changed);
  }
  if (inner) {
    for (size_t l = last; l-- > 0;) polish_level(l, nullptr);
  }
  return moved;
}

/// Rounds of regroup_children and refitting per level in regroup_tree.
constexpr int kRegroupRounds = 3;
/// Directions of the support points that stand for a node's samples in
/// regroup_tree (the reach of a parent, and the fit of a new centre; the
/// radius is always refitted over every sample).
constexpr int kRegroupDirections = 256;

/// Gives every node at most `branching` children, levels from the leaves
/// up: the children of a level keep their spheres; where a parent has too
/// many children, or with `improve` on every level, their parents are chosen
/// anew (regroup_children, with the radius each parent needs about its
/// centre to cover a child's support points), and every node of the level
/// above whose samples changed gets the union of its children's samples and
/// a new centre (the better of a fresh fit and a polish of the old one);
/// kRegroupRounds rounds of both, then, with `protrusion`, every inner node
/// its protrusion polish (until `deadline`; polish_tree leaves the inner
/// nodes to this step). Last, every level is reordered so that siblings are
/// contiguous. Needs #level l <= branching x #level l-1 (the allocation
/// keeps to it). Returns the number of parent changes.
int regroup_tree(const ReductionProblem& dense, const std::vector<const MeshOracle*>& oracles,
                 const ReductionOptions& reduction, const ProtrusionPolishOptions* protrusion,
                 int branching, bool improve, CpuClock::time_point deadline,
                 std::vector<std::vector<Node>>& levels, std::vector<std::vector<int>>& parent_of) {
  const int workers = static_cast<int>(oracles.size());
  // Each node's support points (sample indices, one per direction) stand
  // for its samples: the reach of its parents, and their fits. A level's
  // are folded from the level below's.
  int moved = 0;
  const MatX3d dirs = spiral_directions(kRegroupDirections);
  auto along = [&](Eigen::Index d, int s) {
    return dirs(d, 0) * dense.points(s, 0) + dirs(d, 1) * dense.points(s, 1) +
           dirs(d, 2) * dense.points(s, 2);
  };
  // The support points' coordinates, each sample once.
  auto points_of = [&](std::vector<int> support) {
    std::sort(support.begin(), support.end());
    support.erase(std::unique(support.begin(), support.end()), support.end());
    std::vector<Eigen::Vector3d> out;
    for (int s : support) {
      if (s >= 0) out.push_back(dense.points.row(s).transpose());  // -1: no samples
    }
    return out;
  };
  std::vector<std::vector<int>> extreme(levels.back().size());
  parallel_for(extreme.size(), workers, [&](size_t i, int) {
    extreme[i] = farthest_members(dense.points, levels.back()[i].sphere.members, dirs);
  });
  for (size_t l = levels.size() - 1; l >= 1; --l) {
    std::vector<Node>& nodes = levels[l];
    std::vector<Node>& above = levels[l - 1];
    std::vector<std::vector<int>> above_extreme(above.size());
    // The level above: the union of its children's samples (support points
    // folded from theirs), refitted where it changed.
    auto refit_above = [&]() {
      std::vector<std::vector<int>> unions(above.size());
      std::vector<std::vector<size_t>> kids(above.size());
      for (size_t i = 0; i < nodes.size(); ++i) {
        const auto p = static_cast<size_t>(parent_of[l][i]);
        const auto& m = nodes[i].sphere.members;
        unions[p].insert(unions[p].end(), m.begin(), m.end());
        kids[p].push_back(i);
      }
      parallel_for(above.size(), workers, [&](size_t p, int worker) {
        std::sort(unions[p].begin(), unions[p].end());
        FittedSphere& sp = above[p].sphere;
        std::vector<int>& support = above_extreme[p];
        if (kids[p].empty()) {  // a childless node keeps its sphere
          support = farthest_members(dense.points, sp.members, dirs);
          return;
        }
        // The farthest sample of a union along a direction is one of its parts'.
        support = extreme[kids[p].front()];
        for (Eigen::Index d = 0; d < dirs.rows(); ++d) {
          for (size_t k = 1; k < kids[p].size(); ++k) {
            const int s = extreme[kids[p][k]][static_cast<size_t>(d)];
            int& best = support[static_cast<size_t>(d)];
            if (s >= 0 && (best < 0 || along(d, s) > along(d, best))) best = s;
          }
        }
        if (unions[p] == sp.members) return;
        const std::vector<Eigen::Vector3d> hull = points_of(support);
        const MeshOracle& oracle = *oracles[static_cast<size_t>(worker)];
        FittedSphere kept = sp;
        kept.members = unions[p];
        polish_sphere(dense, oracle, kept);
        FittedSphere fresh = fit_sphere(dense, unions[p], nullptr, reduction, &hull);
        polish_sphere(dense, oracle, fresh);
        sp = fresh.error < kept.error ? std::move(fresh) : std::move(kept);
      });
    };
    // Rounds of regrouping (against the parents' current centres) and refitting.
    std::vector<int> count(above.size(), 0);
    for (int p : parent_of[l]) count[static_cast<size_t>(p)] += 1;
    // Parents are chosen anew where one has too many children, or always with `improve`.
    const bool choose = improve || *std::max_element(count.begin(), count.end()) > branching;
    // The children do not change over the rounds: their support points and
    // largest margins are taken once.
    std::vector<std::vector<Eigen::Vector3d>> support(choose ? nodes.size() : 0);
    std::vector<double> gap(support.size(), 0.0);
    parallel_for(support.size(), workers, [&](size_t i, int) {
      for (int s : nodes[i].sphere.members) gap[i] = std::max(gap[i], dense.gap[s]);
      support[i] = points_of(extreme[i]);
    });
    for (int round = 0; round < (choose ? kRegroupRounds : 1); ++round) {
      if (choose) {
        std::vector<std::vector<double>> reach(nodes.size(), std::vector<double>(above.size()));
        parallel_for(nodes.size(), workers, [&](size_t i, int) {
          for (size_t p = 0; p < above.size(); ++p) {
            double r = 0;
            for (const auto& x : support[i]) r = std::max(r, (x - above[p].sphere.center).norm());
            reach[i][p] = r + gap[i];
          }
        });
        const std::vector<int> parent = regroup_children(reach, parent_of[l], branching);
        int changed = 0;
        for (size_t i = 0; i < parent.size(); ++i) changed += parent[i] != parent_of[l][i] ? 1 : 0;
        moved += changed;
        parent_of[l] = parent;
        if (round > 0 && changed == 0) break;
      }
      refit_above();
    }
    // Every inner node: polish_tree left them to this step.
    if (protrusion != nullptr) {
      parallel_for(above.size(), workers, [&](size_t p, int worker) {
        if (above[p].sphere.members.empty() || !(CpuClock::now() < deadline)) return;
        polish_protrusion(dense, *oracles[static_cast<size_t>(worker)], above[p].sphere,
                          static_cast<unsigned>(1000003 * (l - 1) + p), *protrusion);
      });
    }
    extreme = std::move(above_extreme);
  }
  // Siblings contiguous, in parent order, top-down (stable; each level
  // follows the new order of the one above).
  for (size_t l = 1; l < levels.size(); ++l) {
    std::vector<int> order(levels[l].size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return parent_of[l][static_cast<size_t>(a)] < parent_of[l][static_cast<size_t>(b)];
    });
    std::vector<Node> sorted;
    std::vector<int> sorted_parent, new_index(order.size());
    for (size_t k = 0; k < order.size(); ++k) {
      const auto i = static_cast<size_t>(order[k]);
      sorted.push_back(std::move(levels[l][i]));
      sorted_parent.push_back(parent_of[l][i]);
      new_index[i] = static_cast<int>(k);
    }
    levels[l] = std::move(sorted);
    parent_of[l] = std::move(sorted_parent);
    if (l + 1 < levels.size()) {
      for (int& p : parent_of[l + 1]) p = new_index[static_cast<size_t>(p)];
    }
  }
  return moved;
}

}  // namespace

SphereTreeBuild build_sphere_tree(const SurfaceMesh& input, const SphereTreeOptions& options) {
  check_options(options);
  const auto start = Clock::now();
  const auto cpu_start = CpuClock::now();
  const auto deadline = cpu_start + std::chrono::duration_cast<CpuClock::duration>(
                                        std::chrono::duration<double>(options.time_limit));
  SphereTreeBuild out;
  auto step_start = CpuClock::now();
  auto step_wall_start = Clock::now();
  auto end_step = [&](const char* name) {
    const auto now = CpuClock::now();
    const auto wall = Clock::now();
    out.step_cpu_seconds.emplace_back(name,
                                      std::chrono::duration<double>(now - step_start).count());
    out.step_wall_seconds.emplace_back(
        name, std::chrono::duration<double>(wall - step_wall_start).count());
    step_start = now;
    step_wall_start = wall;
  };
  const SurfaceMesh closed = close_holes(input);
  const MeshOracle oracle(closed);
  // One oracle per worker thread (its inside test is not safe for concurrent use).
  const int workers = worker_count(options.threads);
  std::vector<std::unique_ptr<MeshOracle>> extra_oracles;
  std::vector<const MeshOracle*> oracles{&oracle};
  for (int w = 1; w < workers; ++w) {
    extra_oracles.push_back(std::make_unique<MeshOracle>(closed));
    oracles.push_back(extra_oracles.back().get());
  }
  const double scale = longest_bounding_box_side(closed.V);
  if (!(scale > 0)) throw InputError("build_sphere_tree: the mesh has a degenerate bounding box");

  // Samples: coverage (dense) on the input surface, medial (coarse) on the closed one.
  const SphereTreeOptions::Sampling& sampling = options.sampling;
  out.samples = sample_surface(input.V, input.F, SamplingOptions{sampling.cover_spacing * scale});
  // Medial samples: thin triangles by columns from a saving of 3 (the
  // coverage samples' default 8 would leave most of pinion_small's teeth on
  // the lattice: 303 000 medial samples instead of 87 000); the bunny's and
  // the dragon's triangles stay below it at the medial spacings.
  SamplingOptions medial_sampling{sampling.medial_spacing * scale};
  medial_sampling.column_ratio = 3.0;
  const SurfaceSamples medial_samples = sample_surface(closed.V, closed.F, medial_sampling);
  end_step("hole closing, oracle, sampling");
  MedialAxisOptions medial_options;
  medial_options.refinement_iterations = sampling.refinement_iterations;
  medial_options.error_tolerance = sampling.refinement_tolerance * scale;
  const MedialSpheres medial = approximate_medial_axis(oracles, medial_samples, medial_options);
  out.num_medial_spheres = static_cast<int>(medial.radii.size());
  out.num_refinement_points = medial.num_inserted;
  const PointGrid grid(medial.centers, scale / 64.0);
  end_step("medial axis");
  out.medial_seconds = std::chrono::duration<double>(Clock::now() - start).count();

  // The medial samples drive the placement; their margin is that of the coverage samples.
  const Eigen::VectorXd medial_gap =
      Eigen::VectorXd::Constant(medial_samples.points.rows(), out.samples.gap.maxCoeff());
  const ReductionProblem coarse{medial_samples.points, medial_gap, medial, grid};
  const ReductionProblem dense{out.samples.points, out.samples.gap, medial, grid};
  ReductionOptions reduction;
  reduction.lloyd_iterations = options.reduction.lloyd_iterations;
  reduction.deadline = deadline;
  const int build_branching = std::max(options.branching, options.allocation.build_branching);

  // Root.
  Node root;
  std::vector<int> all_medial(static_cast<size_t>(medial_samples.points.rows()));
  std::iota(all_medial.begin(), all_medial.end(), 0);
  std::vector<int> all_dense(static_cast<size_t>(out.samples.points.rows()));
  std::iota(all_dense.begin(), all_dense.end(), 0);
  root.sphere = fit_sphere(coarse, all_medial, nullptr, reduction);
  root.medial = all_medial;
  {
    std::vector<FittedSphere> one{root.sphere};
    assign_and_refit(dense, all_dense, one);
    polish_sphere(dense, oracle, one.front());
    root.sphere = one.front();
  }

  std::vector<std::vector<Node>> levels{{root}};
  std::vector<std::vector<int>> parent_of{{-1}};
  for (int l = 1; l <= options.depth; ++l) {
    const std::vector<Node>& parents = levels.back();
    std::vector<ParentChoices> choices(parents.size());
    const int max_k = l >= 2 ? build_branching : options.branching;
    // With one parent (the root) its reduction is spread over the workers instead.
    ReductionOptions node_reduction = reduction;
    node_reduction.threads = parents.size() == 1 ? workers : 1;
    parallel_for(parents.size(), workers, [&](size_t p, int) {
      choices[p].configs = reduce_to_spheres(coarse, parents[p].medial, max_k, node_reduction);
    });
    long long cap =
        std::max<long long>(level_cap(options, l), static_cast<long long>(parents.size()));
    // What regroup_tree can place under the parents with `branching` each.
    cap = std::min<long long>(cap, static_cast<long long>(parents.size()) * options.branching);
    std::vector<ChildCountCosts> costs(choices.size());
    for (size_t p = 0; p < choices.size(); ++p) {
      // A parent cannot use more children than it has coverage samples (a
      // child without one is dropped), whatever its medial samples allow.
      // Applied with build_branching only: on the default it changes the
      // trees and measured no better (dragon: mean42 17.16 vs 16.88, worst42
      // <= 80 in 5 of 7 builds).
      const size_t usable = build_branching > options.branching
                                ? std::max<size_t>(1, parents[p].sphere.members.size())
                                : choices[p].configs.size();
      for (const auto& config : choices[p].configs) {
        if (costs[p].worst.size() == usable) break;
        costs[p].worst.push_back(ParentChoices::worst_error(config));
        costs[p].sum.push_back(ParentChoices::total_error(config));
      }
    }
    // The largest worst child bound of the configurations `count` chooses.
    auto chosen_worst = [&](const std::vector<int>& count) {
      double worst = 0;
      for (size_t p = 0; p < costs.size(); ++p)
        worst = std::max(worst, costs[p].worst[static_cast<size_t>(count[p] - 1)]);
      return worst;
    };
    const SphereTreeOptions::Allocation& share = options.allocation;
    AllocationOptions allocation;
    allocation.worst_share = share.worst_share;
    if (l == options.depth && share.leaf_worst_factor > 0) {
      allocation.worst_threshold =
          share.leaf_worst_factor * chosen_worst(allocate_children(costs, cap, allocation));
      if (share.leaf_worst_target > 0) {
        allocation.worst_threshold =
            std::min(allocation.worst_threshold, share.leaf_worst_target * scale);
      }
    } else if (l == options.depth) {
      allocation.worst_threshold = share.leaf_worst_target * scale;
    }
    const std::vector<int> count = allocate_children(costs, cap, allocation);
    out.allocated_worst_bound.push_back(chosen_worst(count));

    // Each parent's children, fitted to its coverage samples: one task per parent.
    std::vector<std::vector<Node>> children_of(parents.size());
    parallel_for(parents.size(), workers, [&](size_t p, int worker) {
      // With one parent (level 1) its children are polished in parallel instead.
      const bool spread = parents.size() == 1;
      auto polish_all = [&](std::vector<FittedSphere>& spheres) {
        parallel_for(spheres.size(), spread ? workers : 1, [&](size_t i, int w) {
          polish_sphere(dense, *oracles[static_cast<size_t>(spread ? w : worker)], spheres[i]);
        });
      };
      std::vector<FittedSphere> kids = choices[p].configs[static_cast<size_t>(count[p] - 1)];
      std::vector<std::vector<int>> kid_medial;
      for (size_t k = 0; k < kids.size(); ++k) {
        kids[k].tag = static_cast<int>(k);
        kid_medial.push_back(kids[k].members);
      }
      // The parent's coverage samples are divided among the children, and each
      // child's radius refitted to cover its share with margin.
      std::vector<FittedSphere> fitted = kids;
      assign_and_refit(dense, parents[p].sphere.members, fitted);
      polish_all(fitted);
      assign_and_refit(dense, parents[p].sphere.members, fitted);
      ExchangeOptions exchange;
      exchange.rounds = 2;
      for (int round = 0; round < options.exchange.sibling_rounds; ++round) {
        shrink_by_exchange(dense, fitted, exchange);
        polish_all(fitted);
      }
      if (options.exchange.sibling_rounds > 0) shrink_by_exchange(dense, fitted, exchange);
      for (auto& f : fitted) {
        Node n;
        n.sphere = std::move(f);
        if (n.sphere.tag >= 0) n.medial = kid_medial[static_cast<size_t>(n.sphere.tag)];
        if (n.medial.empty()) n.medial = parents[p].medial;  // keep the subtree placeable
        children_of[p].push_back(std::move(n));
      }
    });
    std::vector<Node> children;
    std::vector<int> parent_index;
    for (size_t p = 0; p < parents.size(); ++p) {
      for (Node& n : children_of[p]) {
        children.push_back(std::move(n));
        parent_index.push_back(static_cast<int>(p));
      }
    }
    levels.push_back(std::move(children));
    parent_of.push_back(std::move(parent_index));
    end_step(l == 1 ? "level 1" : l == 2 ? "level 2" : l == 3 ? "level 3" : "level > 3");
  }
  // With regrouping ahead, a leaf's parent may take any number of children:
  // only the level's count must fit under the parents with `branching` each.
  const bool regroup = build_branching > options.branching && levels.size() > 2;
  const long long leaf_cap =
      levels.size() < 2
          ? 1
          : std::min<long long>(
                level_cap(options, options.depth),
                static_cast<long long>(levels[levels.size() - 2].size()) * options.branching);
  const int leaf_parent_limit =
      regroup ? static_cast<int>(std::max<long long>(leaf_cap, 2)) : options.branching;
  if (options.reduction.joint_leaf_refinement && levels.size() > 2) {
    refine_leaves(coarse, dense, oracle, out.samples, input.F, reduction, levels, parent_of);
    assert(children_divide_samples(levels, parent_of));
  }
  const SphereTreeOptions::Exchange& exchange = options.exchange;
  if (exchange.across_leaves && levels.size() > 1)
    exchange_across_leaves(dense, oracles, levels, parent_of, 3, exchange.relieve_moves);
  end_step("leaf exchange");
  if (exchange.sum_passes > 0 && levels.size() > 1) {
    const size_t last = levels.size() - 1;
    std::vector<FittedSphere> leaves;
    double worst = 0;
    for (const Node& n : levels[last])
      leaves.push_back(n.sphere), worst = std::max(worst, n.sphere.error);
    auto accepts = [&](int leaf, int s) {
      return ancestors_cover(dense, levels, parent_of, leaf, s);
    };
    SumExchangeOptions sum;
    sum.passes = exchange.sum_passes;
    sum.cap_fraction = exchange.sum_cap;
    lower_error_sum(dense, leaves, exchange.sum_max_share * worst, sum, accepts);
    for (size_t i = 0; i < leaves.size(); ++i) levels[last][i].sphere = std::move(leaves[i]);
    refit_inner_nodes(dense, levels, parent_of);
  }
  end_step("sum exchange");
  if (options.polish.enabled) {
    const auto polish_start = CpuClock::now();
    // With regrouping ahead, the inner nodes are polished after it.
    out.num_polished = polish_tree(dense, oracles, levels, parent_of, options.polish.protrusion,
                                   options.polish.exchange_rounds, deadline, !regroup);
    out.polish_cpu_seconds = std::chrono::duration<double>(CpuClock::now() - polish_start).count();
  }
  end_step("protrusion polish");
  if (options.worst_split.enabled && levels.size() > 1) {
    LeafLevel leaf_level;
    for (Node& n : levels.back()) {
      leaf_level.spheres.push_back(std::move(n.sphere));
      leaf_level.medial.push_back(std::move(n.medial));
    }
    leaf_level.parent = parent_of.back();
    WorstSplitOptions split = options.worst_split.options;
    split.deadline = std::min(split.deadline, deadline);
    out.worst_split = split_worst_leaves(coarse, dense, oracles, reduction, leaf_level,
                                         static_cast<int>(leaf_cap), leaf_parent_limit, split);
    levels.back().clear();
    for (size_t i = 0; i < leaf_level.spheres.size(); ++i) {
      Node n;
      n.sphere = std::move(leaf_level.spheres[i]);
      n.medial = std::move(leaf_level.medial[i]);
      levels.back().push_back(std::move(n));
    }
    parent_of.back() = std::move(leaf_level.parent);
    end_step("worst split");
  }
  if (regroup || (options.allocation.regroup_parents && levels.size() > 2)) {
    out.num_regrouped = regroup_tree(
        dense, oracles, reduction, options.polish.enabled ? &options.polish.protrusion : nullptr,
        options.branching, options.allocation.regroup_parents, deadline, levels, parent_of);
    end_step("regroup");
  }

  assert(children_divide_samples(levels, parent_of));
  // Flatten breadth-first: level by level, children of a node contiguous.
  collision::SphereTree& tree = out.tree;
  int offset = 0;
  std::vector<int> level_start;
  for (const auto& level : levels) {
    level_start.push_back(offset);
    offset += static_cast<int>(level.size());
  }
  level_start.push_back(offset);
  tree.level_offset = level_start;
  for (size_t l = 0; l < levels.size(); ++l) {
    for (size_t i = 0; i < levels[l].size(); ++i) {
      const FittedSphere& s = levels[l][i].sphere;
      collision::Sphere sp{s.center.x(), s.center.y(), s.center.z(), s.radius};
      tree.spheres.push_back(sp);
      tree.rest_spheres.push_back(sp);
      tree.level.push_back(static_cast<int32_t>(l));
      tree.first_child.push_back(-1);
      tree.child_count.push_back(0);
      out.node_samples.push_back(s.members);
      out.node_depth.push_back(s.depth);
    }
  }
  for (size_t l = 1; l < levels.size(); ++l) {
    for (size_t i = 0; i < levels[l].size(); ++i) {
      const int parent = level_start[l - 1] + parent_of[l][i];
      const int node = level_start[l] + static_cast<int>(i);
      if (tree.first_child[static_cast<size_t>(parent)] < 0)
        tree.first_child[static_cast<size_t>(parent)] = node;
      tree.child_count[static_cast<size_t>(parent)] += 1;
    }
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  out.cpu_seconds = std::chrono::duration<double>(CpuClock::now() - cpu_start).count();
  out.hit_time_limit = CpuClock::now() > deadline;
  return out;
}

}  // namespace icd::mesh
