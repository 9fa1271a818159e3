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
#include <exception>
#include <filesystem>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "collision/aabb_tree.hpp"
#include "collision/traversal.hpp"
#include "experiments/common/command_line.hpp"
#include "experiments/spheretree/tree_report.hpp"
#include "mesh/io/surface_reader.hpp"

namespace {

using icd::collision::Sphere;
using icd::collision::SphereTree;

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

/// The rigid motion of the second copy: x -> R (x - c) + c + t u.
struct Pose {
  Eigen::Matrix3d R;
  Eigen::Vector3d c, u;
  Eigen::Vector3d apply(const Eigen::Vector3d& x, double t) const { return R * (x - c) + c + t * u; }
};

/// The largest t at which leaf i of `a` and leaf j of `b` moved by the pose
/// overlap, over all leaf pairs (-inf when none ever does): past it no leaf
/// pair of this tree overlaps, so (for a covering tree) the surfaces are apart.
double last_leaf_overlap(const SphereTree& a, const SphereTree& b, const Pose& pose) {
  const int la = a.num_levels() - 1, lb = b.num_levels() - 1;
  double last = -std::numeric_limits<double>::infinity();
  for (int j = b.level_offset[lb]; j < b.level_offset[lb + 1]; ++j) {
    const Eigen::Vector3d q = pose.apply(b.spheres[j].center(), 0.0);
    for (int i = a.level_offset[la]; i < a.level_offset[la + 1]; ++i) {
      // |q + t u - p| <= ra + rb: t^2 + 2 t u.(q - p) + |q - p|^2 - R^2 <= 0.
      const Eigen::Vector3d d = q - a.spheres[i].center();
      const double R = a.spheres[i].r + b.spheres[j].r;
      const double half_b = pose.u.dot(d), c = d.squaredNorm() - R * R;
      const double disc = half_b * half_b - c;
      if (disc >= 0) last = std::max(last, -half_b + std::sqrt(disc));
    }
  }
  return last;
}

SphereTree moved(const SphereTree& tree, const Pose& pose, double t) {
  SphereTree m = tree;
  for (Sphere& s : m.spheres) {
    const Eigen::Vector3d c = pose.apply(s.center(), t);
    s.x = c.x(), s.y = c.y(), s.z = c.z();
  }
  return m;
}

struct Counts {
  std::vector<int> false_poses;        // per gap: poses with a leaf pair
  std::vector<double> false_leaves;    // per gap: summed leaf pairs
  std::vector<double> upper_pairs;     // per gap: summed level L-1 pairs
  std::vector<double> tests;           // per gap: summed sphere tests of the full traversal
  int missed = 0;                      // crossing poses with no leaf pair
  double crossing_leaves = 0;          // summed leaf pairs at the crossing poses
};

int run(int argc, char** argv) {
  std::filesystem::path mesh_path;
  std::string trees_arg;
  std::vector<double> gaps = {0.5, 1, 2, 4, 8, 16, 32, 64};
  int poses = 100;
  unsigned seed = 1;
  double step = 0.5;
  icd::experiments::CommandLine cli(
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
                  gaps.push_back(icd::experiments::CommandLine::parse_real(g, 0.0));
                  if (!(gaps.back() > 0)) throw std::invalid_argument("must be > 0, got " + g);
                }
                if (gaps.empty()) throw std::invalid_argument("needs at least one gap");
              })
      .real("--step", step, "UNITS", "marching step towards the touching pose (normalized units)");
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

  const icd::MatX3d& VA = mesh.V;
  const icd::collision::AabbTree aabb_a(VA, mesh.F);
  icd::MatX3d VB = VA;
  icd::collision::AabbTree aabb_b(VB, mesh.F);
  auto meshes_meet = [&](const Pose& pose, double t) {
    for (Eigen::Index v = 0; v < VA.rows(); ++v)
      VB.row(v) = pose.apply(VA.row(v).transpose(), t).transpose();
    aabb_b.refit(VB, mesh.F);
    return !icd::collision::intersecting_triangle_pairs(aabb_a, VA, mesh.F, aabb_b, VB, mesh.F)
                .empty();
  };

  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<Counts> counts(trees.size());
  for (auto& c : counts) {
    c.false_poses.assign(gaps.size(), 0);
    c.false_leaves.assign(gaps.size(), 0.0);
    c.upper_pairs.assign(gaps.size(), 0.0);
    c.tests.assign(gaps.size(), 0.0);
  }
  icd::collision::CollisionRequest full;  // no budget: every overlapping leaf pair
  int skipped = 0;
  for (int k = 0; k < poses; ++k) {
    Pose pose;
    Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
    pose.R = q.normalized().toRotationMatrix();
    pose.u = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    pose.c = centre;
    // From where no leaf pair of any tree overlaps, march in until the
    // surfaces cross, then bisect between the last apart and the first crossing.
    double hi = -std::numeric_limits<double>::infinity();
    for (const auto& t : trees) hi = std::max(hi, last_leaf_overlap(t.tree, t.tree, pose));
    hi += 1.0 / to_2000;
    if (meshes_meet(pose, hi)) {  // no tree covers this contact: cannot start from outside
      ++skipped;
      continue;
    }
    double lo = hi;
    while (!meshes_meet(pose, lo)) hi = lo, lo -= step / to_2000;
    for (int it = 0; it < 40 && hi - lo > 1e-4 / to_2000; ++it) {
      const double mid = 0.5 * (lo + hi);
      (meshes_meet(pose, mid) ? lo : hi) = mid;
    }
    const double touch = hi;  // apart here, crossing 1e-4 units further in
    for (size_t ti = 0; ti < trees.size(); ++ti) {
      const SphereTree& a = trees[ti].tree;
      Counts& c = counts[ti];
      const auto crossing = icd::collision::collide(a, moved(a, pose, lo), full);
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
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "contact_tightness: " << e.what() << "\n";
    return 1;
  }
}
