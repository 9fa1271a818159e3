// Sphere-tree builder on small meshes (sphere, box, torus): layout, coverage
// of every level (margin bookkeeping and an independent dense random
// sampling checked by brute force), error decreasing level to level,
// determinism (also across thread counts), and option checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Geometry>

#include "collision/contact_oracle.hpp"
#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/builder.hpp>
#include <icd/mesh/spheres/evaluation.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/protrusion.hpp>

namespace {

using namespace icd::mesh;

struct Case {
  std::string name;
  icd::SurfaceMesh mesh;
};

std::vector<Case> cases() {
  return {{"icosphere", icd::make_icosphere(2)},
          {"box", icd::make_box_surface({0, 0, 0}, {2, 1, 0.6})},
          {"torus", icd::make_torus(1.0, 0.3, 24, 12)}};
}

SphereTreeOptions small_options() {
  SphereTreeOptions o;
  o.branching = 4;
  o.depth = 2;
  o.sampling.cover_spacing = 1.0 / 80;
  o.sampling.medial_spacing = 1.0 / 20;
  return o;
}

/// The builds of cases(), made once per test program (each takes seconds).
const SphereTreeBuild& cached_build(const Case& c) {
  static std::map<std::string, SphereTreeBuild> builds;
  auto it = builds.find(c.name);
  if (it == builds.end())
    it = builds.emplace(c.name, build_sphere_tree(c.mesh, small_options())).first;
  return it->second;
}

/// Random surface points, uniform by area (independent of the builder's lattice).
icd::MatX3d dense_random_points(const icd::SurfaceMesh& m, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<double> cumulative;
  double total = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative.push_back(total);
  }
  std::uniform_real_distribution<double> u(0, 1);
  icd::MatX3d P(count, 3);
  for (int i = 0; i < count; ++i) {
    const auto f = static_cast<Eigen::Index>(
        std::lower_bound(cumulative.begin(), cumulative.end(), u(rng) * total) -
        cumulative.begin());
    double s = u(rng), t = u(rng);
    if (s + t > 1) s = 1 - s, t = 1 - t;
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    P.row(i) = a + s * (b - a) + t * (c - a);
  }
  return P;
}

/// Every node of `build` covers its samples with their margins, the root
/// holds every sample once, and the children of every inner node divide its
/// samples among them (none empty, no sample in two children), so each node
/// covers the union of its children's patches.
void expect_nodes_cover_and_children_divide(const SphereTreeBuild& build) {
  const auto& tree = build.tree;
  const auto& P = build.samples.points;
  ASSERT_EQ(static_cast<int>(build.node_samples.size()), tree.num_nodes());
  std::vector<int> all(static_cast<size_t>(P.rows()));
  std::iota(all.begin(), all.end(), 0);
  std::vector<int> root = build.node_samples[0];
  std::sort(root.begin(), root.end());
  EXPECT_EQ(root, all) << "the root must hold every sample exactly once";
  for (int i = 0; i < tree.num_nodes(); ++i) {
    const auto& s = tree.spheres[i];
    for (int m : build.node_samples[i]) {
      ASSERT_LE((P.row(m).transpose() - s.center()).norm() + build.samples.gap[m],
                s.r * (1 + 1e-12) + 1e-12);
    }
    if (tree.child_count[i] == 0) continue;
    std::vector<int> joined;
    for (int k = 0; k < tree.child_count[i]; ++k) {
      const auto& cs = build.node_samples[tree.first_child[i] + k];
      EXPECT_FALSE(cs.empty());
      joined.insert(joined.end(), cs.begin(), cs.end());
    }
    std::sort(joined.begin(), joined.end());
    EXPECT_EQ(joined, build.node_samples[i]) << "children must divide the samples of node " << i;
  }
}

/// How many points of `P` no sphere of level `l` of `tree` contains (brute force).
int uncovered_on_level(const icd::collision::SphereTree& tree, int l, const icd::MatX3d& P) {
  int uncovered = 0;
  for (Eigen::Index p = 0; p < P.rows(); ++p) {
    bool covered = false;
    for (int i = tree.level_offset[l]; i < tree.level_offset[l + 1] && !covered; ++i) {
      covered = (P.row(p).transpose() - tree.spheres[i].center()).norm() <= tree.spheres[i].r;
    }
    uncovered += covered ? 0 : 1;
  }
  return uncovered;
}

TEST(SphereTreeBuilder, LayoutIsBreadthFirstWithContiguousChildren) {
  for (const auto& c : cases()) {
    SCOPED_TRACE(c.name);
    const SphereTreeBuild& build = cached_build(c);
    const auto& tree = build.tree;
    EXPECT_NO_THROW(icd::collision::validate(tree));
    ASSERT_EQ(tree.num_levels(), 3);
    EXPECT_EQ(tree.level_offset[0], 0);
    EXPECT_EQ(tree.level_offset[1], 1);
    EXPECT_LE(tree.level_offset[2] - tree.level_offset[1], 4);
    EXPECT_LE(tree.level_offset[3] - tree.level_offset[2], 16);
    int expected_next = 1;
    for (int i = 0; i < tree.num_nodes(); ++i) {
      EXPECT_GE(tree.level[i], 0);
      EXPECT_TRUE(i >= tree.level_offset[tree.level[i]] &&
                  i < tree.level_offset[tree.level[i] + 1]);
      if (tree.child_count[i] == 0) {
        EXPECT_EQ(tree.first_child[i], -1);
        EXPECT_EQ(tree.level[i], 2) << "leaves are on the last level";
        continue;
      }
      EXPECT_LE(tree.child_count[i], 4);
      EXPECT_EQ(tree.first_child[i], expected_next)
          << "children must follow in breadth-first order";
      expected_next += tree.child_count[i];
      for (int k = 0; k < tree.child_count[i]; ++k)
        EXPECT_EQ(tree.level[tree.first_child[i] + k], tree.level[i] + 1);
    }
    EXPECT_EQ(expected_next, tree.num_nodes());
  }
}

TEST(SphereTreeBuilder, EveryNodeCoversItsSamplesWithMarginAndChildrenDivideThem) {
  for (const auto& c : cases()) {
    SCOPED_TRACE(c.name);
    const SphereTreeBuild& build = cached_build(c);
    expect_nodes_cover_and_children_divide(build);
    ASSERT_FALSE(build.node_samples.empty());
    EXPECT_EQ(static_cast<Eigen::Index>(build.node_samples[0].size()), build.samples.points.rows());
  }
}

TEST(SphereTreeBuilder, EveryLevelCoversAnIndependentDenseSampling) {
  for (const auto& c : cases()) {
    SCOPED_TRACE(c.name);
    const SphereTreeBuild& build = cached_build(c);
    const auto& tree = build.tree;
    const icd::MatX3d P = dense_random_points(c.mesh, 20000, 7);
    for (int l = 0; l < tree.num_levels(); ++l)
      EXPECT_EQ(uncovered_on_level(tree, l, P), 0) << "level " << l;
  }
}

TEST(SphereTreeBuilder, ErrorDecreasesFromLevelToLevel) {
  EvaluationOptions eval;
  eval.coverage_spacing = 10.0;
  for (const auto& c : cases()) {
    SCOPED_TRACE(c.name);
    const SphereTreeBuild& build = cached_build(c);
    const auto metrics = evaluate_sphere_tree(c.mesh, build.tree, eval);
    ASSERT_EQ(metrics.size(), 3u);
    for (size_t l = 1; l < metrics.size(); ++l) {
      // The sphere is already fitted exactly by its root (error = margin only).
      const double slack = c.name == "icosphere" ? 0.01 * 2000 : 0.0;
      EXPECT_LE(metrics[l].mean_error_162, metrics[l - 1].mean_error_162 + slack) << "level " << l;
      EXPECT_LE(metrics[l].worst_error_162, metrics[l - 1].worst_error_162 + slack)
          << "level " << l;
      if (c.name != "icosphere") {
        EXPECT_LT(metrics[l].mean_error_162, 0.8 * metrics[l - 1].mean_error_162);
      }
      EXPECT_EQ(metrics[l].num_uncovered_samples, 0);
      EXPECT_EQ(metrics[l].num_uncovered_vertices, 0);
    }
  }
}

SphereTreeOptions lossy_leaf_options();

TEST(SphereTreeBuilder, JointLeafRefinementKeepsEveryGuarantee) {
  // The joint option moves leaves across parents (a leaf may lose all its
  // samples and is then removed) and refits the inner nodes bottom-up: every
  // node must still cover its samples with margin, children divide their
  // parent's samples, and every level covers a dense sampling. Every small
  // case, with the small options and with coarse medial samples under
  // branching 8 (leaves of very different sizes).
  for (const Case& c : cases()) {
    for (int variant = 0; variant < 2; ++variant) {
      SCOPED_TRACE(c.name + (variant == 0 ? " small options" : " lossy options"));
      SphereTreeOptions o = variant == 0 ? small_options() : lossy_leaf_options();
      o.reduction.joint_leaf_refinement = true;
      const SphereTreeBuild build = build_sphere_tree(c.mesh, o);
      const auto& tree = build.tree;
      EXPECT_NO_THROW(icd::collision::validate(tree));
      for (int i = 0; i < tree.num_nodes(); ++i) EXPECT_LE(tree.child_count[i], o.branching);
      expect_nodes_cover_and_children_divide(build);
      const icd::MatX3d D = dense_random_points(c.mesh, 5000, 11);
      for (int l = 0; l < tree.num_levels(); ++l)
        EXPECT_EQ(uncovered_on_level(tree, l, D), 0) << "level " << l;
    }
  }
}

/// Options of the leaf-budget tests: the icosphere's coarse medial samples
/// with branching 8 make the top-down pass lose leaves, so the worst-leaf
/// split has free slots to use.
SphereTreeOptions lossy_leaf_options() {
  SphereTreeOptions o = small_options();
  o.branching = 8;
  o.sampling.medial_spacing = 1.0 / 6;
  o.worst_split.options.measure_directions = 300;
  o.worst_split.options.choice_directions = 100;
  // The cases below were set up (to exercise splits and failed tries) with
  // the fixed-split leaf allocation.
  o.allocation.leaf_worst_target = 0;
  o.allocation.leaf_worst_factor = 0;
  return o;
}

/// Every level of `tree` covers a dense random sampling of `mesh` (brute force).
void expect_every_level_covers(const icd::collision::SphereTree& tree, const icd::SurfaceMesh& mesh,
                               unsigned seed) {
  const icd::MatX3d D = dense_random_points(mesh, 5000, seed);
  for (int l = 0; l < tree.num_levels(); ++l)
    EXPECT_EQ(uncovered_on_level(tree, l, D), 0) << "level " << l;
}

/// Protrusion of each leaf of `tree` on `directions` (recomputed here with
/// sphere_protrusion, independently of the builder's bookkeeping).
std::vector<double> leaf_protrusions(const icd::collision::SphereTree& tree,
                                     const MeshOracle& oracle, const icd::MatX3d& directions) {
  std::vector<double> e;
  for (int i = tree.level_offset[tree.num_levels() - 1]; i < tree.num_nodes(); ++i)
    e.push_back(sphere_protrusion(oracle, tree.spheres[i].center(), tree.spheres[i].r, directions));
  return e;
}

double leaf_worst_protrusion(const icd::collision::SphereTree& tree, const MeshOracle& oracle,
                             const icd::MatX3d& directions) {
  const std::vector<double> e = leaf_protrusions(tree, oracle, directions);
  return e.empty() ? 0.0 : std::max(0.0, *std::max_element(e.begin(), e.end()));
}

/// The guarantees of split_worst_leaves on the 3-level `build` of `mesh`
/// with options `o`, against the same build without it (`plain`): the leaf
/// count bookkeeping (plain + splits - merges), at most `cap` leaves, the
/// branching, coverage with margin and children dividing their parent's
/// samples, every level covering a dense random sampling (`seed`), and the
/// true worst on the measuring directions, recomputed here, equal to the
/// reported one and not above the start's.
void expect_worst_split_guarantees(const SphereTreeBuild& plain, const SphereTreeBuild& build,
                                   const icd::SurfaceMesh& mesh, const SphereTreeOptions& o,
                                   int cap, unsigned seed) {
  const auto& tree = build.tree;
  const auto& r = build.worst_split;
  const int leaves = tree.num_nodes() - tree.level_offset[2];
  EXPECT_EQ(leaves, plain.tree.num_nodes() - plain.tree.level_offset[2] + r.splits - r.merges);
  EXPECT_LE(leaves, cap);
  for (int i = 0; i < tree.num_nodes(); ++i) EXPECT_LE(tree.child_count[i], o.branching);
  expect_nodes_cover_and_children_divide(build);
  expect_every_level_covers(tree, mesh, seed);
  const MeshOracle oracle(mesh);
  const icd::MatX3d dirs = spiral_directions(o.worst_split.options.measure_directions);
  const double before = leaf_worst_protrusion(plain.tree, oracle, dirs);
  const double after = leaf_worst_protrusion(tree, oracle, dirs);
  EXPECT_NEAR(r.worst_before, before, 1e-12);
  EXPECT_NEAR(r.worst_after, after, 1e-12);
  EXPECT_LE(after, before);
  EXPECT_LE(r.worst_after, r.worst_before);
}

TEST(SphereTreeBuilder, SplitWorstKeepsEveryGuaranteeAndNeverRaisesTheTrueWorst) {
  // The worst-leaf split is the last step, so the build without it is the
  // tree it starts from. On this sphere (coarse medial samples, branching 8)
  // the top-down pass loses leaves, so there is room for splits. Checked:
  // leaf count within the cap and each parent within its branching, the
  // leaf count bookkeeping (+1 per split, -1 per merge), every node covers
  // its samples with margin and children divide their parent's samples,
  // every level covers a dense random sampling (brute force), and the
  // largest leaf protrusion on the measuring directions, recomputed here,
  // equals the reported one and is not above the start's.
  const icd::SurfaceMesh sphere = icd::make_icosphere(2);
  SphereTreeOptions o = lossy_leaf_options();
  o.worst_split.enabled = false;
  const SphereTreeBuild plain = build_sphere_tree(sphere, o);
  o.worst_split.enabled = true;
  const SphereTreeBuild build = build_sphere_tree(sphere, o);
  const auto& tree = build.tree;
  EXPECT_NO_THROW(icd::collision::validate(tree));
  ASSERT_EQ(tree.num_levels(), 3);
  const auto& result = build.worst_split;
  EXPECT_GT(result.splits, 0) << "the case must exercise the split";
  EXPECT_LT(plain.tree.level_offset[3] - plain.tree.level_offset[2], 64);
  expect_worst_split_guarantees(plain, build, sphere, o, 64, 17);
  // Inner levels are untouched: the split divides a leaf's samples.
  for (int i = 0; i < tree.level_offset[2]; ++i) {
    EXPECT_EQ(tree.spheres[i].r, plain.tree.spheres[i].r);
    EXPECT_EQ(build.node_samples[i], plain.node_samples[i]);
  }
}

TEST(SphereTreeBuilder, SplitWorstBelowTheReliefBandDoesNotRaiseTheMeanBeyondItsBound) {
  // Without the relief band (relief_fraction > 1) a split is kept only when
  // it adds at most the level's starting mean true error (on the choice
  // directions) to the summed true error (on the measuring directions), and
  // no merge happens. Recomputed here with sphere_protrusion on both leaf
  // levels: the starting mean, and sum_after <= sum_before + splits * mean.
  const icd::SurfaceMesh sphere = icd::make_icosphere(2);
  SphereTreeOptions o = lossy_leaf_options();
  o.worst_split.options.relief_fraction = 2.0;
  const SphereTreeBuild plain = [&] {
    SphereTreeOptions p = o;
    p.worst_split.enabled = false;
    return build_sphere_tree(sphere, p);
  }();
  o.worst_split.enabled = true;
  const SphereTreeBuild build = build_sphere_tree(sphere, o);
  const auto& result = build.worst_split;
  EXPECT_GT(result.splits, 0) << "the case must exercise the split";
  EXPECT_EQ(result.merges, 0);
  const MeshOracle oracle(sphere);
  const icd::MatX3d measure = spiral_directions(o.worst_split.options.measure_directions);
  const icd::MatX3d choice = spiral_directions(o.worst_split.options.choice_directions);
  auto leaf_sum = [&](const icd::collision::SphereTree& tree, const icd::MatX3d& dirs) {
    const std::vector<double> e = leaf_protrusions(tree, oracle, dirs);
    return std::accumulate(e.begin(), e.end(), 0.0);
  };
  const int plain_leaves = plain.tree.num_nodes() - plain.tree.level_offset[2];
  const double mean_before = leaf_sum(plain.tree, choice) / plain_leaves;
  EXPECT_NEAR(result.mean_before, mean_before, 1e-12 * (1 + mean_before));
  EXPECT_LE(leaf_sum(build.tree, measure),
            leaf_sum(plain.tree, measure) + result.splits * mean_before + 1e-9);
  EXPECT_EQ(build.tree.num_nodes() - build.tree.level_offset[2], plain_leaves + result.splits);
}

TEST(SphereTreeBuilder, SplitWorstRejectsBadOptions) {
  const auto box = icd::make_box_surface({0, 0, 0}, {1, 1, 1});
  SphereTreeOptions o = small_options();
  o.worst_split.enabled = true;
  o.worst_split.options.measure_directions = 0;
  EXPECT_THROW(build_sphere_tree(box, o), icd::ParameterError);
  o.worst_split.options.measure_directions = 10;
  o.worst_split.options.max_tries = -1;
  EXPECT_THROW(build_sphere_tree(box, o), icd::ParameterError);
}

TEST(SphereTreeBuilder, ProtrusionPolishNeverRaisesANodesError) {
  // The polish is the last step: the same build without it has the same
  // nodes; each polished node protrudes no more (measured on the polish's
  // check directions, recomputed here: the polish keeps only moves that lower
  // it, and the exchange between its leaf passes only shrinks radii), and
  // some protrude less.
  const Case torus = cases()[2];
  SphereTreeOptions o = small_options();
  o.worst_split.enabled = false;  // the polish is then the last step
  const SphereTreeBuild polished = build_sphere_tree(torus.mesh, o);
  o.polish.enabled = false;
  const SphereTreeBuild plain = build_sphere_tree(torus.mesh, o);
  ASSERT_EQ(plain.tree.num_nodes(), polished.tree.num_nodes());
  EXPECT_EQ(plain.tree.level_offset, polished.tree.level_offset);
  EXPECT_EQ(plain.node_samples.front(), polished.node_samples.front());
  EXPECT_GT(polished.num_polished, 0);
  const MeshOracle oracle(torus.mesh);
  const icd::MatX3d check = spiral_directions(o.polish.protrusion.check_directions);
  double sum_plain = 0, sum_polished = 0;
  for (int i = 0; i < plain.tree.num_nodes(); ++i) {
    const auto& a = plain.tree.spheres[i];
    const auto& b = polished.tree.spheres[i];
    const double ea = sphere_protrusion(oracle, a.center(), a.r, check);
    const double eb = sphere_protrusion(oracle, b.center(), b.r, check);
    EXPECT_LE(eb, ea + 1e-12) << "node " << i;
    sum_plain += ea, sum_polished += eb;
  }
  EXPECT_LT(sum_polished, sum_plain);
}

TEST(SphereTreeBuilder, IsDeterministic) {
  const Case torus = cases()[2];
  const auto& a = cached_build(torus).tree;
  const auto b = build_sphere_tree(torus.mesh, small_options()).tree;
  ASSERT_EQ(a.num_nodes(), b.num_nodes());
  for (int i = 0; i < a.num_nodes(); ++i) {
    EXPECT_EQ(a.spheres[i].x, b.spheres[i].x);
    EXPECT_EQ(a.spheres[i].y, b.spheres[i].y);
    EXPECT_EQ(a.spheres[i].z, b.spheres[i].z);
    EXPECT_EQ(a.spheres[i].r, b.spheres[i].r);
  }
  EXPECT_EQ(a.first_child, b.first_child);
}

TEST(SphereTreeBuilder, DoesNotDependOnTheThreadCount) {
  // Parallel steps (a parent's children, the protrusion polish, the leaf
  // polish between exchanges, split_worst_leaves' candidate divisions of a
  // leaf) work on one node or candidate per task: one thread and three give
  // the same tree, bit for bit.
  const Case torus = cases()[2];
  SphereTreeOptions one = small_options(), three = small_options();
  one.threads = 1;
  three.threads = 3;
  const SphereTreeBuild a = build_sphere_tree(torus.mesh, one);
  const SphereTreeBuild b = build_sphere_tree(torus.mesh, three);
  ASSERT_GT(a.worst_split.tries, 0) << "the case must exercise split_worst_leaves";
  EXPECT_EQ(a.worst_split.splits, b.worst_split.splits);
  EXPECT_EQ(a.worst_split.measured, b.worst_split.measured);
  ASSERT_EQ(a.tree.num_nodes(), b.tree.num_nodes());
  ASSERT_GT(a.tree.num_nodes(), 5);
  for (int i = 0; i < a.tree.num_nodes(); ++i) {
    EXPECT_EQ(a.tree.spheres[i].x, b.tree.spheres[i].x) << i;
    EXPECT_EQ(a.tree.spheres[i].y, b.tree.spheres[i].y) << i;
    EXPECT_EQ(a.tree.spheres[i].z, b.tree.spheres[i].z) << i;
    EXPECT_EQ(a.tree.spheres[i].r, b.tree.spheres[i].r) << i;
  }
  EXPECT_EQ(a.tree.first_child, b.tree.first_child);
  EXPECT_EQ(a.tree.child_count, b.tree.child_count);
  EXPECT_EQ(a.node_samples, b.node_samples);
  EXPECT_EQ(a.num_polished, b.num_polished);
  one.threads = -1;
  EXPECT_THROW(build_sphere_tree(torus.mesh, one), icd::ParameterError);
}

TEST(SphereTreeBuilder, RespectsSphereCapsPerLevel) {
  SphereTreeOptions o = small_options();
  o.max_spheres_per_level = {1, 3, 7};
  const auto build = build_sphere_tree(icd::make_torus(1.0, 0.3, 24, 12), o);
  EXPECT_LE(build.tree.level_offset[2] - build.tree.level_offset[1], 3);
  EXPECT_LE(build.tree.level_offset[3] - build.tree.level_offset[2], 7);
  EXPECT_NO_THROW(icd::collision::validate(build.tree));
}

TEST(SphereTreeBuilder, LeafWorstTargetMeetsAFeasibleThresholdAndKeepsEveryGuarantee) {
  // The threshold rule at the leaf level (leaf_worst_target). The fixed
  // split's (worst_share) leaf allocation within the cap reaches a largest
  // worst child bound W, so a target of 1.2 W is feasible (every parent's
  // fewest children below it are at most its count there): the threshold
  // build's largest allocated bound must be <= the target. Level 1 keeps the
  // fixed split (same bound). Both a feasible and an unreachable target
  // (1e-9) keep every guarantee: caps, nodes cover their samples with
  // margin, children divide them, every level covers a dense random sampling
  // (brute force). leaf_worst_factor 1.2 (1.2 times the fixed split's own
  // bound) must meet the same threshold.
  const icd::SurfaceMesh torus = icd::make_torus(1.0, 0.3, 24, 12);
  SphereTreeOptions o = small_options();
  o.max_spheres_per_level = {1, 4, 10};
  o.worst_split.enabled = false;  // the steps after the allocation are tested elsewhere
  o.polish.enabled = false;
  o.allocation.leaf_worst_target = 0;  // the fixed split
  o.allocation.leaf_worst_factor = 0;
  const SphereTreeBuild plain = build_sphere_tree(torus, o);
  ASSERT_EQ(plain.allocated_worst_bound.size(), 2u);
  const double scale = (torus.V.colwise().maxCoeff() - torus.V.colwise().minCoeff()).maxCoeff();
  const double target = 1.2 * plain.allocated_worst_bound[1];
  ASSERT_GT(target, 0);
  for (const double relative : {target / scale, 1e-9}) {
    SCOPED_TRACE(relative);
    o.allocation.leaf_worst_target = relative;
    const SphereTreeBuild build = build_sphere_tree(torus, o);
    const auto& tree = build.tree;
    EXPECT_NO_THROW(icd::collision::validate(tree));
    ASSERT_EQ(tree.num_levels(), 3);
    ASSERT_EQ(build.allocated_worst_bound.size(), 2u);
    EXPECT_EQ(build.allocated_worst_bound[0], plain.allocated_worst_bound[0]);
    if (relative > 1e-6) {
      EXPECT_LE(build.allocated_worst_bound[1], target * (1 + 1e-12));
    }
    EXPECT_LE(tree.level_offset[3] - tree.level_offset[2], 10);
    for (int i = 0; i < tree.num_nodes(); ++i) EXPECT_LE(tree.child_count[i], o.branching);
    expect_nodes_cover_and_children_divide(build);
    expect_every_level_covers(tree, torus, 19);
  }
  // The same threshold as a factor on the fixed split's own bound.
  o.allocation.leaf_worst_target = 0;
  o.allocation.leaf_worst_factor = 1.2;
  const SphereTreeBuild by_factor = build_sphere_tree(torus, o);
  ASSERT_EQ(by_factor.allocated_worst_bound.size(), 2u);
  EXPECT_LE(by_factor.allocated_worst_bound[1], target * (1 + 1e-12));
  expect_nodes_cover_and_children_divide(by_factor);
  o.allocation.leaf_worst_factor = -1;
  EXPECT_THROW(build_sphere_tree(torus, o), icd::ParameterError);
  o.allocation.leaf_worst_factor = 0;
  o.allocation.leaf_worst_target = -0.1;
  EXPECT_THROW(build_sphere_tree(torus, o), icd::ParameterError);
}

TEST(SphereTreeBuilder, BuildBranchingRegroupsToTheBranchingAndKeepsEveryGuarantee) {
  // Built with up to 8 children per parent below level 1, then regrouped to
  // branching 3 (leaves under level 2, level 2 under level 1): the regrouping
  // must have moved nodes, and the tree must keep its branching, its caps,
  // coverage with margin with children dividing their parent's samples, and
  // every level covering a dense random sampling (brute force); and it must
  // not depend on the thread count (1 and 3 threads).
  const icd::SurfaceMesh torus = icd::make_torus(1.0, 0.3, 24, 12);
  SphereTreeOptions o = small_options();
  o.branching = 3;
  o.depth = 3;
  o.max_spheres_per_level = {1, 3, 7, 19};
  o.allocation.build_branching = 8;
  o.threads = 1;
  const SphereTreeBuild build = build_sphere_tree(torus, o);
  const auto& tree = build.tree;
  EXPECT_NO_THROW(icd::collision::validate(tree));
  ASSERT_EQ(tree.num_levels(), 4);
  EXPECT_GT(build.num_regrouped, 0) << "the case must exercise the regrouping";
  for (int i = 0; i < tree.num_nodes(); ++i) EXPECT_LE(tree.child_count[i], o.branching);
  for (int l = 1; l < 4; ++l)
    EXPECT_LE(tree.level_offset[l + 1] - tree.level_offset[l], o.max_spheres_per_level[l]);
  expect_nodes_cover_and_children_divide(build);
  expect_every_level_covers(tree, torus, 23);
  o.threads = 3;
  const SphereTreeBuild threaded = build_sphere_tree(torus, o);
  EXPECT_EQ(threaded.node_samples, build.node_samples);
  EXPECT_EQ(threaded.tree.child_count, tree.child_count);
  o.allocation.build_branching = 2;  // below the branching
  EXPECT_THROW(build_sphere_tree(torus, o), icd::ParameterError);
}

TEST(SphereTreeBuilder, RegroupParentsKeepsTheLeavesAndEveryGuarantee) {
  // After the joint pass, regroup_parents chooses every node's parent anew:
  // the leaf spheres must be exactly those of the same build without it (it
  // moves whole leaves, never their samples), some leaf must have changed
  // parent (the case exercises it), and the tree must keep its branching,
  // coverage with margin with children dividing their parent's samples, and
  // every level covering a dense random sampling (brute force); the inner
  // level's radii, the objective, must sum to less. The icosphere with coarse
  // medial samples under branching 8 (leaves of very different sizes): its
  // joint pass moves leaves across parents.
  const icd::SurfaceMesh sphere = icd::make_icosphere(2);
  SphereTreeOptions o = lossy_leaf_options();
  o.reduction.joint_leaf_refinement = true;
  const SphereTreeBuild plain = build_sphere_tree(sphere, o);
  o.allocation.regroup_parents = true;
  const SphereTreeBuild build = build_sphere_tree(sphere, o);
  const auto& tree = build.tree;
  EXPECT_NO_THROW(icd::collision::validate(tree));
  ASSERT_EQ(tree.num_levels(), 3);
  EXPECT_GT(build.num_regrouped, 0) << "the case must exercise the regrouping";
  for (int i = 0; i < tree.num_nodes(); ++i) EXPECT_LE(tree.child_count[i], o.branching);
  expect_nodes_cover_and_children_divide(build);
  expect_every_level_covers(tree, sphere, 29);
  // The same leaves (sphere and samples), in some order.
  auto leaves = [](const SphereTreeBuild& b) {
    std::vector<std::tuple<std::vector<int>, double, double, double, double>> out;
    for (int i = b.tree.level_offset[2]; i < b.tree.level_offset[3]; ++i) {
      const auto& s = b.tree.spheres[i];
      out.emplace_back(b.node_samples[i], s.x, s.y, s.z, s.r);
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(leaves(build), leaves(plain));
  auto inner_radii = [](const SphereTreeBuild& b) {
    double sum = 0;
    for (int i = b.tree.level_offset[1]; i < b.tree.level_offset[2]; ++i)
      sum += b.tree.spheres[i].r;
    return sum;
  };
  EXPECT_LT(inner_radii(build), inner_radii(plain));
}

TEST(SphereTreeBuilder, ParentFilterFindsEveryContactOfInterlockedWrappedTrees) {
  // The query's parent filter (CollisionRequest::parent_filter) is
  // conservative because every node covers its subtree's surface patch, which
  // the builder guarantees; its trees are wrapped (children stick out of their
  // parents), so the filter prunes pairs here. Two copies of the torus' tree,
  // the second turned 90 degrees about x and moved through the first's tube.
  const Case torus = cases()[2];
  SphereTreeOptions o = small_options();
  o.depth = 3;  // the filter's first test that can fail: a leaf against a level-1 node
  const icd::collision::SphereTree ta = build_sphere_tree(torus.mesh, o).tree;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Vector3d shift(1.9, 0.1, 0.05);
  icd::SurfaceMesh b = torus.mesh;
  b.V = (b.V * R.transpose()).eval();
  b.V.rowwise() += shift.transpose();
  icd::collision::SphereTree tb = ta;
  for (auto& sp : tb.spheres) {
    const Eigen::Vector3d c = R * sp.center() + shift;
    sp.x = c.x(), sp.y = c.y(), sp.z = c.z();
  }
  tb.rest_spheres = tb.spheres;
  const auto points = icd::collision::testing::contact_points(torus.mesh.V, torus.mesh.F, b.V, b.F);
  // Every contact point under a reported pair, every mode, with and without
  // the filter, at every test budget.
  icd::collision::testing::check_all_budgets(ta, tb, points);
  icd::collision::CollisionRequest filtered;
  filtered.parent_filter = true;
  const auto plain_result = icd::collision::collide(ta, tb, icd::collision::CollisionRequest{});
  const auto filtered_result = icd::collision::collide(ta, tb, filtered);
  EXPECT_LT(filtered_result.colliding.size(), plain_result.colliding.size());
}

TEST(SphereTreeBuilder, RejectsBadOptionsAndMeshes) {
  const auto box = icd::make_box_surface({0, 0, 0}, {1, 1, 1});
  SphereTreeOptions o = small_options();
  o.branching = 1;
  EXPECT_THROW(build_sphere_tree(box, o), icd::ParameterError);
  o = small_options();
  o.depth = -1;
  EXPECT_THROW(build_sphere_tree(box, o), icd::ParameterError);
  o = small_options();
  o.time_limit = 0;
  EXPECT_THROW(build_sphere_tree(box, o), icd::ParameterError);
  EXPECT_THROW(build_sphere_tree(icd::SurfaceMesh{}, small_options()), icd::InputError);
}

}  // namespace
