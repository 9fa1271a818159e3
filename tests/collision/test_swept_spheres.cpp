// Swept spheres: the relative-motion test against dense sampling in time,
// and a swept query that finds two trees crossing each other between two
// instants where they are apart.
#include <gtest/gtest.h>

#include <random>

#include <icd/collision/octree_tree.hpp>
#include <icd/collision/swept_spheres.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::collision {
namespace {

double sampled_gap(const SweptSphere& a, const SweptSphere& b) {
  double best = 1e300;
  for (int k = 0; k <= 20000; ++k) {
    const double t = k / 20000.0;
    const Eigen::Vector3d ca(a.x + t * a.dx, a.y + t * a.dy, a.z + t * a.dz);
    const Eigen::Vector3d cb(b.x + t * b.dx, b.y + t * b.dy, b.z + t * b.dz);
    best = std::min(best, (ca - cb).norm() - a.r - b.r);
  }
  return best;
}

TEST(SweptSpheres, OverlapMatchesSamplingInTime) {
  std::mt19937 rng{0};
  std::uniform_real_distribution<double> u(-1, 1), r(0.01, 0.3);
  int agree = 0;
  for (int i = 0; i < 2000; ++i) {
    const SweptSphere a{u(rng), u(rng), u(rng), 2 * u(rng), 2 * u(rng), 2 * u(rng), r(rng)};
    const SweptSphere b{u(rng), u(rng), u(rng), 2 * u(rng), 2 * u(rng), 2 * u(rng), r(rng)};
    const double gap = sampled_gap(a, b);
    if (std::abs(gap) < 1e-3) continue;  // too close to call by sampling
    EXPECT_EQ(swept_overlap(a, b), gap < 0) << "case " << i;
    ++agree;
  }
  EXPECT_GT(agree, 1900);
}

TEST(SweptSpheres, SweepCoversStartEndAndVia) {
  const std::vector<Sphere> from{{0, 0, 0, 0.1}}, to{{1, 0, 0, 0.2}}, via{{0.5, 0.3, 0, 0.05}};
  std::vector<SweptSphere> s;
  EXPECT_NEAR(sweep_spheres(from, to, s), 1.1, 1e-12);
  EXPECT_NEAR(s[0].r, 0.2, 1e-9);
  sweep_spheres(from, to, s, via);
  EXPECT_NEAR(s[0].r, 0.35, 1e-9);
  EXPECT_THROW(sweep_spheres(from, {}, s), std::exception);
}

// Two icosphere trees 0.4 apart at the start, on the other side of each other
// at the end: apart at both instants, touching in between.
TEST(SweptSpheres, QueryFindsTreesThatCrossBetweenTwoInstants) {
  const SurfaceMesh m = make_icosphere(2, 0.1);
  OctreeTreeOptions o;
  o.levels = 4;
  const SphereTree t = build_octree_tree(m.V, m.F, o);
  auto moved = [&](double x) {
    std::vector<Sphere> s = t.spheres;
    for (Sphere& q : s) q.x += x;
    return s;
  };
  std::vector<SweptSphere> a, b;
  std::vector<NodePair> stack;
  sweep_spheres(moved(-0.3), moved(0.3), a);
  sweep_spheres(moved(0.3), moved(-0.3), b);
  const SweptResult hit = swept_contact(t, a, t, b, {}, stack);
  EXPECT_TRUE(hit.touched);
  EXPECT_FALSE(hit.gave_up);
  EXPECT_TRUE(t.is_leaf(hit.first.a) && t.is_leaf(hit.first.b));
  // Side by side (0.3 apart in y) at every instant: no contact.
  std::vector<SweptSphere> c = b;
  for (SweptSphere& q : c) q.y += 0.3;
  EXPECT_FALSE(swept_contact(t, a, t, c, {}, stack).touched);
  // A budget too small to decide answers "touched".
  SweptRequest tiny;
  tiny.budget_tests = 3;
  const SweptResult capped = swept_contact(t, a, t, b, tiny, stack);
  EXPECT_TRUE(capped.touched && capped.gave_up);
}

}  // namespace
}  // namespace icd::collision
