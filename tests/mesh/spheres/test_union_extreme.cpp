// union_extreme_points (the merge search of split_worst_leaves fits sibling
// pairs from their own extreme points): checked against the hull of all
// members of the union (member_extreme_points), and fit_sphere given them
// against fit_sphere computing them itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>

#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/medial_axis.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/reduction.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

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

TEST(UnionExtreme, MemberExtremePointsAreTheHullVertices) {
  // member_extreme_points prefilters sets of over 1000 members before the
  // exact hull: checked against brute force over all members. Every point
  // it returns is a member, they reach as far along each of 5000 random
  // directions as the members do, and the farthest of them from random
  // points is as far as the farthest member.
  const TorusProblem t;
  const auto n = static_cast<int>(t.samples.points.rows());
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss;
  auto random_unit = [&] {
    Eigen::Vector3d d(gauss(rng), gauss(rng), gauss(rng));
    return d.normalized();
  };
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<int> members;
    const Eigen::Vector3d normal = random_unit();
    for (int s = 0; s < n; ++s) {
      const double v = normal.dot(t.samples.points.row(s).transpose());
      if (trial == 0 || v < 0.3 * trial) members.push_back(s);
    }
    ASSERT_GT(members.size(), 1000u) << "trial " << trial;
    const auto extreme = member_extreme_points(t.problem, members);
    const auto sorted = as_sorted(extreme);
    std::vector<Eigen::Vector3d> all;
    for (int s : members) all.emplace_back(t.samples.points.row(s).transpose());
    const auto sorted_all = as_sorted(all);
    for (const auto& p : sorted)
      EXPECT_TRUE(std::binary_search(sorted_all.begin(), sorted_all.end(), p));
    EXPECT_LT(extreme.size(), members.size() / 4) << "trial " << trial;
    // Up to rounding: samples inside a flat hull facet (a mesh triangle on
    // the hull) tie with its corners but are no hull vertices.
    for (int k = 0; k < 5000; ++k) {
      const Eigen::Vector3d d = random_unit();
      double brute = -1e300, fast = -1e300;
      for (const auto& p : all) brute = std::max(brute, p.dot(d));
      for (const auto& p : extreme) fast = std::max(fast, p.dot(d));
      ASSERT_NEAR(fast, brute, 1e-12) << "trial " << trial << ": a hull vertex is missing";
    }
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector3d c = 2.0 * random_unit() * std::abs(gauss(rng));
      double brute = 0, fast = 0;
      for (const auto& p : all) brute = std::max(brute, (p - c).norm());
      for (const auto& p : extreme) fast = std::max(fast, (p - c).norm());
      EXPECT_NEAR(fast, brute, 1e-12) << "trial " << trial;
    }
  }
}

}  // namespace
