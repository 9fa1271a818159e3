// union_extreme_points (the merge search of split_worst_leaves fits sibling
// pairs from their own extreme points): checked against the hull of all
// members of the union (member_extreme_points), and fit_sphere given them
// against fit_sphere computing them itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>

#include "mesh/io/primitives.hpp"
#include "mesh/spheres/medial_axis.hpp"
#include "mesh/spheres/mesh_oracle.hpp"
#include "mesh/spheres/reduction.hpp"
#include "mesh/spheres/surface_sampling.hpp"

namespace {

using namespace icd::mesh;

/// Points as sortable triples (exact comparison: the same doubles).
std::vector<std::array<double, 3>> as_sorted(const std::vector<Eigen::Vector3d>& pts) {
  std::vector<std::array<double, 3>> out;
  for (const auto& p : pts) out.push_back({p.x(), p.y(), p.z()});
  std::sort(out.begin(), out.end());
  return out;
}

struct TorusProblem {
  icd::SurfaceMesh torus = icd::make_torus(1.0, 0.35, 32, 16);
  MeshOracle oracle{torus};
  SurfaceSamples samples = sample_surface(torus.V, torus.F, SamplingOptions{0.05});
  MedialSpheres medial = approximate_medial_axis(oracle, samples, MedialAxisOptions{});
  PointGrid grid{medial.centers, 0.2};
  ReductionProblem problem{samples.points, samples.gap, medial, grid};
};

TEST(UnionExtreme, SameSetAsTheHullOfAllMembers) {
  const TorusProblem t;
  const auto n = static_cast<int>(t.samples.points.rows());
  ASSERT_GT(n, 2000);
  std::mt19937 rng(11);
  // Pairs of member sets: two halves of the torus cut by a plane (adjacent
  // siblings), two random interleaved sets, and a small pair (<= 64 members).
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<int> a, b;
    if (trial < 2) {
      const Eigen::Vector3d normal = Eigen::Vector3d::Random().normalized();
      for (int s = 0; s < n; ++s) {
        const double v = normal.dot(t.samples.points.row(s).transpose());
        if (v < -0.5)
          a.push_back(s);
        else if (v < 0.6)
          b.push_back(s);
      }
    } else {
      std::bernoulli_distribution coin(0.5);
      const int count = trial == 2 ? n : 60;
      for (int s = 0; s < count; ++s) (coin(rng) ? a : b).push_back(s);
    }
    ASSERT_FALSE(a.empty());
    ASSERT_FALSE(b.empty());
    std::vector<int> all = a;
    all.insert(all.end(), b.begin(), b.end());
    std::sort(all.begin(), all.end());
    const auto oracle_points = member_extreme_points(t.problem, all);
    const auto hull = union_extreme_points(t.problem, all, member_extreme_points(t.problem, a),
                                           member_extreme_points(t.problem, b));
    EXPECT_EQ(as_sorted(hull), as_sorted(oracle_points)) << "trial " << trial;
    // The fit from the given extreme points is the fit computed from scratch.
    const FittedSphere plain = fit_sphere(t.problem, all, nullptr, ReductionOptions{});
    const FittedSphere given = fit_sphere(t.problem, all, nullptr, ReductionOptions{}, &hull);
    EXPECT_NEAR((plain.center - given.center).norm(), 0.0, 1e-12) << "trial " << trial;
    EXPECT_NEAR(plain.radius, given.radius, 1e-12) << "trial " << trial;
    EXPECT_NEAR(plain.error, given.error, 1e-12) << "trial " << trial;
    EXPECT_EQ(plain.members, given.members);
  }
}

}  // namespace
