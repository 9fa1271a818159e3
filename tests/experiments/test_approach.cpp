// The geometry of contact_tightness (experiments/studies/spheretree/approach.hpp)
// against independent references: the exact contact of two boxes by the
// separating-axis theorem, and a dense scan of the leaf pairs' distances.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <vector>

#include <Eigen/Geometry>

#include <icd/collision/sph_io.hpp>
#include "experiments/studies/spheretree/approach.hpp"
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::experiments {
namespace {

const Eigen::Vector3d kHalf(1.0, 0.6, 0.3);  // half extents of the test box

/// The box [-kHalf, kHalf] and its copy turned by pose.R about the origin
/// and moved by t u overlap (closed solids) for |t| <= this (separating
/// axes: face normals of both and their cross products).
double boxes_touch_at(const ApproachPose& pose) {
  std::vector<Eigen::Vector3d> axes;
  for (int i = 0; i < 3; ++i) {
    axes.push_back(Eigen::Vector3d::Unit(i));
    axes.push_back(pose.R.col(i));
    for (int j = 0; j < 3; ++j) axes.push_back(Eigen::Vector3d::Unit(i).cross(pose.R.col(j)));
  }
  double touch = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& L : axes) {
    if (L.norm() < 1e-9) continue;
    double reach = 0;
    for (int i = 0; i < 3; ++i)
      reach += kHalf[i] * (std::abs(L[i]) + std::abs(L.dot(pose.R.col(i))));
    const double along = std::abs(L.dot(pose.u));
    if (along > 1e-15) touch = std::min(touch, reach / along);
  }
  return touch;
}

std::vector<ApproachPose> poses(int count) {
  RandomApproachPoses random(5, Eigen::Vector3d::Zero());
  std::vector<ApproachPose> out;
  for (int k = 0; k < count; ++k) out.push_back(random.next());
  return out;
}

TEST(SelfApproach, SurfacesMeetExactlyWhereTheBoxesOverlap) {
  const SurfaceMesh box = make_box_surface(-kHalf, kHalf);
  SelfApproach surfaces(box.V, box.F);
  for (const ApproachPose& pose : poses(20)) {
    const double t = boxes_touch_at(pose);
    ASSERT_TRUE(std::isfinite(t));
    for (double rel : {1e-6, 1e-2, 0.5}) {
      SCOPED_TRACE(rel);
      EXPECT_FALSE(surfaces.meets(pose, t * (1 + rel)));
      EXPECT_FALSE(surfaces.meets(pose, -t * (1 + rel)));
      // Equal boxes turned against each other: overlapping solids means
      // crossing surfaces (neither can hold the other).
      EXPECT_TRUE(surfaces.meets(pose, t * (1 - rel)));
      EXPECT_TRUE(surfaces.meets(pose, -t * (1 - rel)));
    }
  }
}

TEST(FindTouching, BracketsTheExactTouchingPoseOfTwoBoxes) {
  const SurfaceMesh box = make_box_surface(-kHalf, kHalf);
  SelfApproach surfaces(box.V, box.F);
  for (const ApproachPose& pose : poses(20)) {
    const double exact = boxes_touch_at(pose);
    const Touching found =
        find_touching([&](double t) { return surfaces.meets(pose, t); }, exact + 0.37, 0.05, 1e-7);
    ASSERT_TRUE(found.found);
    EXPECT_LE(found.apart - found.crossing, 1e-7);
    EXPECT_LE(found.crossing, exact + 1e-12);
    EXPECT_GE(found.apart, exact - 1e-12);
  }
  // Meeting at the start already: nothing found.
  const ApproachPose pose = poses(1).front();
  EXPECT_FALSE(
      find_touching([&](double t) { return surfaces.meets(pose, t); }, 0.0, 0.05, 1e-7).found);
  auto never = [](double) { return false; };
  auto always = [](double) { return true; };
  EXPECT_THROW(find_touching(never, 1.0, 0.0, 1e-7), ParameterError);
  EXPECT_THROW(find_touching(always, 1.0, 0.05, std::nan("")), ParameterError);
}

/// A two-level tree (root and `leaves` random leaves) through the .sph reader.
collision::SphereTree random_tree(std::mt19937& rng, int leaves) {
  std::uniform_real_distribution<double> pos(-1, 1), rad(0.05, 0.4);
  std::ostringstream sph;
  sph << "2 " << leaves << "\n0 0 0 3 0\n";
  for (int i = 0; i < leaves; ++i)
    sph << pos(rng) << " " << pos(rng) << " " << pos(rng) << " " << rad(rng) << " 0\n";
  std::istringstream in(sph.str());
  return collision::read_sph(in);
}

/// Smallest distance minus radii over the leaf pairs of `a` and `b` moved by the pose at t.
double leaf_clearance(const collision::SphereTree& a, const collision::SphereTree& b,
                      const ApproachPose& pose, double t) {
  double clearance = std::numeric_limits<double>::infinity();
  for (int i = a.level_offset[1]; i < a.level_offset[2]; ++i)
    for (int j = b.level_offset[1]; j < b.level_offset[2]; ++j)
      clearance = std::min(clearance,
                           (pose.apply(b.spheres[j].center(), t) - a.spheres[i].center()).norm() -
                               a.spheres[i].r - b.spheres[j].r);
  return clearance;
}

TEST(LastLeafOverlap, IsTheLargestParameterWithAnOverlappingLeafPair) {
  std::mt19937 rng(3);
  RandomApproachPoses random(4, Eigen::Vector3d(0.1, -0.2, 0.3));
  int never = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const collision::SphereTree a = random_tree(rng, 5), b = random_tree(rng, 4);
    const ApproachPose pose = random.next();
    const double last = last_leaf_overlap(a, b, pose);
    if (!std::isfinite(last)) {  // no leaf pair on a crossing course: none ever overlaps
      EXPECT_EQ(last, -std::numeric_limits<double>::infinity());
      for (double t = -10; t < 10; t += 1e-3) ASSERT_GT(leaf_clearance(a, b, pose, t), 0.0);
      ++never;
      continue;
    }
    EXPECT_NEAR(leaf_clearance(a, b, pose, last), 0.0, 1e-9);  // a pair touches there
    // and none overlaps at any larger t (dense scan well past every pair).
    for (double dt = 1e-6; dt < 10; dt += 1e-3)
      ASSERT_GT(leaf_clearance(a, b, pose, last + dt), 0.0) << "t = last + " << dt;
  }
  EXPECT_LE(never, 5) << "most trials must have leaf pairs that meet";
  // Leaves that pass each other: never.
  std::istringstream one("2 1\n0 0 0 2 0\n0 0 0 1 0\n"), far("2 1\n0 5 0 2 0\n0 5 0 1 0\n");
  const collision::SphereTree a = collision::read_sph(one), b = collision::read_sph(far);
  ApproachPose along_x;  // identity turn, u = x: centres stay 5 apart sideways
  EXPECT_EQ(last_leaf_overlap(a, b, along_x), -std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace icd::experiments
