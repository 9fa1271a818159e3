#include "mesh/spheres/builder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <queue>
#include <string>

#include "mesh/io/error.hpp"
#include "mesh/spheres/medial_axis.hpp"
#include "mesh/spheres/mesh_oracle.hpp"
#include "mesh/spheres/point_grid.hpp"

namespace icd::mesh {
namespace {

using Clock = std::chrono::steady_clock;

void check_options(const SphereTreeOptions& o) {
  auto fail = [](const std::string& what) { throw ParameterError("SphereTreeOptions::" + what); };
  if (o.branching < 2) fail("branching must be >= 2, got " + std::to_string(o.branching));
  if (o.depth < 0 || o.depth > 8) fail("depth must be in [0, 8], got " + std::to_string(o.depth));
  if (!(o.cover_spacing > 0) || !(o.medial_spacing >= o.cover_spacing)) {
    fail("cover_spacing must be > 0 and medial_spacing >= cover_spacing");
  }
  if (o.refinement_iterations < 0) fail("refinement_iterations must be >= 0");
  if (!(o.refinement_tolerance > 0)) fail("refinement_tolerance must be > 0");
  if (o.lloyd_iterations < 0) fail("lloyd_iterations must be >= 0");
  if (!(o.time_limit > 0)) fail("time_limit must be > 0 seconds");
}

/// A node under construction: its sphere and its samples (coverage and medial).
struct Node {
  FittedSphere sphere;        // members = coverage samples
  std::vector<int> medial;    // medial (coarse) samples
};

/// The children a parent gets for each child count k (configs[k - 1]).
struct ParentChoices {
  std::vector<std::vector<FittedSphere>> configs;  // on the medial samples
  static double total_error(const std::vector<FittedSphere>& c) {
    double sum = 0;
    for (const auto& s : c) sum += s.error;
    return sum;
  }
};

/// How many children each parent gets under a total cap: start with one each,
/// then repeatedly give one more to the parent whose summed child error drops most.
std::vector<int> allocate_children(const std::vector<ParentChoices>& choices, int cap) {
  std::vector<int> count(choices.size(), 1);
  long long total = static_cast<long long>(choices.size());
  using Item = std::pair<double, size_t>;
  std::priority_queue<Item> heap;
  auto gain = [&](size_t p) {
    const int k = count[p];
    const auto& cfg = choices[p].configs;
    if (k >= static_cast<int>(cfg.size())) return -1.0;
    return ParentChoices::total_error(cfg[static_cast<size_t>(k - 1)]) -
           ParentChoices::total_error(cfg[static_cast<size_t>(k)]);
  };
  for (size_t p = 0; p < choices.size(); ++p) heap.emplace(gain(p), p);
  while (total < cap && !heap.empty()) {
    const auto [g, p] = heap.top();
    heap.pop();
    if (count[p] >= static_cast<int>(choices[p].configs.size())) continue;
    (void)g;
    count[p] += 1;
    ++total;
    heap.emplace(gain(p), p);
  }
  return count;
}

}  // namespace

SphereTreeBuild build_sphere_tree(const SurfaceMesh& input, const SphereTreeOptions& options) {
  check_options(options);
  const auto start = Clock::now();
  const auto deadline = start + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(options.time_limit));
  SphereTreeBuild out;
  const SurfaceMesh closed = close_holes(input);
  const MeshOracle oracle(closed);
  const double scale = longest_bounding_box_side(closed.V);
  if (!(scale > 0)) throw InputError("build_sphere_tree: the mesh has a degenerate bounding box");

  // Samples: coverage (dense) on the input surface, medial (coarse) on the closed one.
  out.samples = sample_surface(input.V, input.F, SamplingOptions{options.cover_spacing * scale});
  const SurfaceSamples medial_samples = sample_surface(closed.V, closed.F, SamplingOptions{options.medial_spacing * scale});
  MedialAxisOptions medial_options;
  medial_options.refinement_iterations = options.refinement_iterations;
  medial_options.error_tolerance = options.refinement_tolerance * scale;
  const MedialSpheres medial = approximate_medial_axis(oracle, medial_samples, medial_options);
  out.num_medial_spheres = static_cast<int>(medial.radii.size());
  out.num_refinement_points = medial.num_inserted;
  const PointGrid grid(medial.centers, scale / 64.0);

  // The medial samples drive the placement; their margin is that of the coverage samples.
  const Eigen::VectorXd medial_gap = Eigen::VectorXd::Constant(medial_samples.points.rows(), out.samples.gap.maxCoeff());
  const ReductionProblem coarse{medial_samples.points, medial_gap, medial, grid};
  const ReductionProblem dense{out.samples.points, out.samples.gap, medial, grid};
  ReductionOptions reduction;
  reduction.lloyd_iterations = options.lloyd_iterations;
  reduction.deadline = deadline;

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
    root.sphere = one.front();
  }

  std::vector<std::vector<Node>> levels{{root}};
  std::vector<std::vector<int>> parent_of{{-1}};
  for (int l = 1; l <= options.depth; ++l) {
    const std::vector<Node>& parents = levels.back();
    std::vector<ParentChoices> choices(parents.size());
    for (size_t p = 0; p < parents.size(); ++p) {
      choices[p].configs = reduce_to_spheres(coarse, parents[p].medial, options.branching, reduction);
    }
    long long cap = 1;
    for (int i = 0; i < l; ++i) cap *= options.branching;
    if (static_cast<int>(options.max_spheres_per_level.size()) > l && options.max_spheres_per_level[static_cast<size_t>(l)] > 0) {
      cap = std::min<long long>(cap, options.max_spheres_per_level[static_cast<size_t>(l)]);
    }
    cap = std::max<long long>(cap, static_cast<long long>(parents.size()));
    const std::vector<int> count = allocate_children(choices, static_cast<int>(std::min<long long>(cap, 1LL << 30)));

    std::vector<Node> children;
    std::vector<int> parent_index;
    for (size_t p = 0; p < parents.size(); ++p) {
      std::vector<FittedSphere> kids = choices[p].configs[static_cast<size_t>(count[p] - 1)];
      std::vector<std::vector<int>> kid_medial;
      for (auto& k : kids) kid_medial.push_back(k.members);
      // The parent's coverage samples are divided among the children, and each
      // child's radius refitted to cover its share with margin.
      std::vector<FittedSphere> fitted = kids;
      assign_and_refit(dense, parents[p].sphere.members, fitted);
      for (auto& f : fitted) {
        Node n;
        n.sphere = std::move(f);
        for (size_t k = 0; k < kids.size(); ++k) {
          if (kids[k].center == n.sphere.center && kids[k].depth == n.sphere.depth) {
            n.medial = kid_medial[k];
            break;
          }
        }
        if (n.medial.empty()) n.medial = parents[p].medial;  // keep the subtree placeable
        children.push_back(std::move(n));
        parent_index.push_back(static_cast<int>(p));
      }
    }
    levels.push_back(std::move(children));
    parent_of.push_back(std::move(parent_index));
  }

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
      if (tree.first_child[static_cast<size_t>(parent)] < 0) tree.first_child[static_cast<size_t>(parent)] = node;
      tree.child_count[static_cast<size_t>(parent)] += 1;
    }
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  out.hit_time_limit = Clock::now() > deadline;
  return out;
}

}  // namespace icd::mesh
