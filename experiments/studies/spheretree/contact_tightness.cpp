// contact_tightness MESH --trees NAME=TREE.sph[:centred],... [--poses N] [--seed S]
//                   [--gaps G1,G2,...] [--step UNITS]
//
// How tight sphere trees are where it matters for contact (issue 5): two
// copies of MESH, the second turned by a random rotation, approach along a
// random direction until their surfaces first touch (exact triangle-triangle
// tests, marched in steps of --step units from where no leaf pair of any
// tree can overlap, then bisected). At the touching pose moved back by each
// gap g (normalized units: longest bounding-box side 2000) the surfaces do
// not meet, so every leaf pair a full traversal of two copies of a tree
// reports there is a false contact. Per tree and gap: the share of poses with
// a false contact at the leaf level, the mean number of false leaf pairs and
// of level L-1 pairs (the answer of a query interrupted there); and, slightly
// past the touching pose (surfaces crossing), the poses where the tree
// reports no leaf pair (a missed contact: the tree does not cover the
// surface there). The same poses for every tree.
// --centred: that tree's coordinates are centred on the mesh's bounding-box
// centre (makeTreeMedial's output; see evaluate_sph).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <icd/collision/traversal.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/studies/spheretree/approach.hpp"
#include "experiments/studies/spheretree/tree_report.hpp"
#include <icd/mesh/io/surface_reader.hpp>

namespace {

using icd::collision::SphereTree;
using icd::experiments::ApproachPose;
using icd::experiments::last_leaf_overlap;
using icd::experiments::moved;

struct NamedTree {
  std::string name;
  SphereTree tree;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, sep);)
    if (!item.empty()) out.push_back(item);
  return out;
}

struct Counts {
  std::vector<int> false_poses;      // per gap: poses with a leaf pair
  std::vector<double> false_leaves;  // per gap: summed leaf pairs
  std::vector<double> upper_pairs;   // per gap: summed level L-1 pairs
  std::vector<double> tests;         // per gap: summed sphere tests of the full traversal
  int missed = 0;                    // crossing poses with no leaf pair
  double crossing_leaves = 0;        // summed leaf pairs at the crossing poses
};

int run(int argc, char** argv) {
  std::filesystem::path mesh_path;
  std::string trees_arg;
  std::vector<double> gaps = {0.5, 1, 2, 4, 8, 16, 32, 64};
  int poses = 100;
  unsigned seed = 1;
  double step = 0.5;
  int parent_filter = 0;
  icd::experiments::Cli cli(
      "contact_tightness",
      "  False contacts of sphere trees on two copies of a mesh approaching each other.");
  cli.argument("MESH", mesh_path, "surface mesh (OFF, OBJ, PLY, STL) the trees were built for",
               true);
  cli.text("--trees", trees_arg, "NAME=TREE.sph[:centred],...", "the trees to compare (required)")
      .integer("--poses", poses, "N", "random approach poses", 1)
      .integer("--seed", seed, "S", "seed of the poses")
      .custom("--gaps", "G,...", "gaps past the touching pose (normalized units, > 0)",
              [&](const std::string& v) {
                gaps.clear();
                for (const std::string& g : split(v, ',')) {
                  gaps.push_back(icd::experiments::Cli::parse_real(g, 0.0));
                  if (!(gaps.back() > 0)) throw std::invalid_argument("must be > 0, got " + g);
                }
                if (gaps.empty()) throw std::invalid_argument("needs at least one gap");
              })
      .real("--step", step, "UNITS", "marching step towards the touching pose (normalized units)")
      .integer("--parent-filter", parent_filter, "0|1",
               "traverse with CollisionRequest::parent_filter", 0, 1);
  if (const auto status = cli.parse(argc, argv)) return *status;
  if (!(step > 0)) throw std::invalid_argument("--step must be > 0");

  const icd::SurfaceMesh mesh = icd::read_surface_mesh(mesh_path);
  const double to_2000 = icd::experiments::to_normalized_units(mesh);
  const Eigen::Vector3d centre = icd::experiments::bounding_box_centre(mesh);
  std::vector<NamedTree> trees;
  for (const std::string& item : split(trees_arg, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw std::invalid_argument("--trees: expected NAME=TREE.sph[:centred], got '" + item + "'");
    std::string path = item.substr(eq + 1);
    bool centred = false;
    if (path.size() > 8 && path.substr(path.size() - 8) == ":centred")
      centred = true, path.resize(path.size() - 8);
    trees.push_back({item.substr(0, eq), icd::experiments::read_sph_for_mesh(path, mesh, centred)});
  }
  if (trees.empty()) throw std::invalid_argument("--trees: at least one tree is needed");

  icd::experiments::SelfApproach surfaces(mesh.V, mesh.F);
  icd::experiments::RandomApproachPoses random_poses(seed, centre);
  std::vector<Counts> counts(trees.size());
  for (auto& c : counts) {
    c.false_poses.assign(gaps.size(), 0);
    c.false_leaves.assign(gaps.size(), 0.0);
    c.upper_pairs.assign(gaps.size(), 0.0);
    c.tests.assign(gaps.size(), 0.0);
  }
  icd::collision::CollisionRequest full;  // no budget: every overlapping leaf pair
  full.parent_filter = parent_filter != 0;
  int skipped = 0;
  for (int k = 0; k < poses; ++k) {
    const ApproachPose pose = random_poses.next();
    // From where no leaf pair of any tree overlaps, march in until the
    // surfaces cross, then bisect between the last apart and the first crossing.
    double start = -std::numeric_limits<double>::infinity();
    for (const auto& t : trees) start = std::max(start, last_leaf_overlap(t.tree, t.tree, pose));
    start += 1.0 / to_2000;
    const auto touching = icd::experiments::find_touching(
        [&](double t) { return surfaces.meets(pose, t); }, start, step / to_2000, 1e-4 / to_2000);
    if (!touching.found) {  // no tree covers this contact: cannot start from outside
      ++skipped;
      continue;
    }
    const double touch = touching.apart, past = touching.crossing;  // 1e-4 units apart
    for (size_t ti = 0; ti < trees.size(); ++ti) {
      const SphereTree& a = trees[ti].tree;
      Counts& c = counts[ti];
      const auto crossing = icd::collision::collide(a, moved(a, pose, past), full);
      c.missed += crossing.colliding.empty() ? 1 : 0;
      c.crossing_leaves += static_cast<double>(crossing.colliding.size());
      for (size_t g = 0; g < gaps.size(); ++g) {
        const SphereTree b = moved(a, pose, touch + gaps[g] / to_2000);
        const auto leaves = icd::collision::collide(a, b, full);
        c.false_poses[g] += leaves.colliding.empty() ? 0 : 1;
        c.false_leaves[g] += static_cast<double>(leaves.colliding.size());
        c.tests[g] += static_cast<double>(leaves.tests);
        icd::collision::CollisionRequest capped;
        capped.depth_cap = a.num_levels() - 2;
        capped.parent_filter = full.parent_filter;
        const auto upper = icd::collision::collide(a, b, capped);
        c.upper_pairs[g] += static_cast<double>(upper.untested.size() + upper.colliding.size());
      }
    }
  }
  const int used = poses - skipped;
  std::printf(
      "# contact_tightness: %s, %d poses (seed %u; %d skipped: surfaces crossing where no leaf "
      "pair overlaps), gaps in normalized units (longest side 2000)\n",
      mesh_path.string().c_str(), used, seed, skipped);
  std::printf(
      "# false%%: poses with a leaf pair at the gap; leaves: mean leaf pairs; upper: mean pairs of "
      "level L-1; tests: mean sphere tests of the full traversal; missed: crossing poses without a "
      "leaf pair\n");
  std::printf("%-12s %6s %8s %9s %9s %9s\n", "tree", "gap", "false%", "leaves", "upper", "tests");
  for (size_t ti = 0; ti < trees.size(); ++ti) {
    const Counts& c = counts[ti];
    for (size_t g = 0; g < gaps.size(); ++g) {
      std::printf("%-12s %6g %7.1f%% %9.2f %9.2f %9.1f\n", trees[ti].name.c_str(), gaps[g],
                  used > 0 ? 100.0 * c.false_poses[g] / used : 0.0,
                  used > 0 ? c.false_leaves[g] / used : 0.0,
                  used > 0 ? c.upper_pairs[g] / used : 0.0, used > 0 ? c.tests[g] / used : 0.0);
    }
    std::printf("%-12s crossing: missed %d of %d poses, mean leaf pairs %.2f\n",
                trees[ti].name.c_str(), c.missed, used, used > 0 ? c.crossing_leaves / used : 0.0);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("contact_tightness", run, argc, argv);
}
