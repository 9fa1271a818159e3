// Exchange lowering the summed error bound (lower_error_sum), checked by
// brute force on torus samples: every sample stays covered with margin and in
// exactly one sphere, radii are the exact covering radii, the summed error
// bound drops, no receiver passes the error cap, the receiver predicate holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/medial_axis.hpp>
#include <icd/mesh/spheres/sum_exchange.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

namespace {

using namespace icd::mesh;

/// Spheres around random sample points, each covering the samples nearest
/// to it with margin; depth 0.1 (a valid, unbalanced configuration).
std::vector<FittedSphere> spheres_around(const SurfaceSamples& s, int k, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Eigen::Index> pick(0, s.points.rows() - 1);
  std::vector<FittedSphere> spheres(static_cast<size_t>(k));
  for (auto& sp : spheres) sp.center = s.points.row(pick(rng)).transpose() * 0.9;
  for (Eigen::Index i = 0; i < s.points.rows(); ++i) {
    size_t best = 0;
    for (size_t j = 1; j < spheres.size(); ++j) {
      if ((s.points.row(i).transpose() - spheres[j].center).norm() <
          (s.points.row(i).transpose() - spheres[best].center).norm())
        best = j;
    }
    spheres[best].members.push_back(static_cast<int>(i));
  }
  spheres.erase(std::remove_if(spheres.begin(), spheres.end(),
                               [](const FittedSphere& sp) { return sp.members.empty(); }),
                spheres.end());
  for (auto& sp : spheres) {
    for (int m : sp.members)
      sp.radius = std::max(sp.radius, (s.points.row(m).transpose() - sp.center).norm() + s.gap[m]);
    sp.depth = 0.1;
    sp.error = sp.radius - sp.depth;
  }
  return spheres;
}

TEST(SumExchange, LowersTheSummedBoundAndKeepsCoverage) {
  const auto torus = icd::make_torus(1.0, 0.3, 24, 12);
  const auto samples = sample_surface(torus.V, torus.F, SamplingOptions{0.05});
  const MedialSpheres medial;  // unused by the exchange
  const PointGrid grid(samples.points, 0.5);
  const ReductionProblem problem{samples.points, samples.gap, medial, grid};
  for (unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    std::vector<FittedSphere> spheres = spheres_around(samples, 14, seed);
    double sum_before = 0, worst_before = 0;
    for (const auto& sp : spheres)
      sum_before += sp.error, worst_before = std::max(worst_before, sp.error);
    const double cap = 0.9 * worst_before;
    // Receivers with an even index only.
    auto accepts = [](int receiver, int) { return receiver % 2 == 0; };
    const auto before = spheres;
    SumExchangeOptions options;
    options.passes = 3;
    const int moves = lower_error_sum(problem, spheres, cap, options, accepts);
    EXPECT_GT(moves, 0);
    std::vector<int> owner(static_cast<size_t>(samples.points.rows()), -1);
    double sum_after = 0;
    for (size_t j = 0; j < spheres.size(); ++j) {
      const auto& sp = spheres[j];
      EXPECT_TRUE(std::is_sorted(sp.members.begin(), sp.members.end()));
      EXPECT_FALSE(sp.members.empty());
      double radius = 0;
      for (int m : sp.members) {
        EXPECT_EQ(owner[static_cast<size_t>(m)], -1) << "sample in two spheres";
        owner[static_cast<size_t>(m)] = static_cast<int>(j);
        radius = std::max(radius,
                          (samples.points.row(m).transpose() - sp.center).norm() + samples.gap[m]);
        const auto& old = before[j].members;
        if (!std::binary_search(old.begin(), old.end(), m)) {
          EXPECT_EQ(j % 2, 0u) << "sample " << m << " moved to a refused receiver";
        }
      }
      EXPECT_NEAR(sp.radius, radius, 1e-12);
      EXPECT_NEAR(sp.error, sp.radius - sp.depth, 1e-12);
      EXPECT_EQ(sp.center, before[j].center);
      if (sp.radius > before[j].radius) {
        EXPECT_LE(sp.error, cap + 1e-12);
      }
      sum_after += sp.error;
    }
    EXPECT_EQ(std::count(owner.begin(), owner.end(), -1), 0) << "a sample lost its sphere";
    EXPECT_LT(sum_after, sum_before);
  }
}

TEST(SumExchange, RejectsBadOptions) {
  const MedialSpheres medial;
  const icd::MatX3d P = icd::MatX3d::Zero(1, 3);
  const Eigen::VectorXd gap = Eigen::VectorXd::Zero(1);
  const PointGrid grid(P, 1.0);
  const ReductionProblem problem{P, gap, medial, grid};
  std::vector<FittedSphere> spheres;
  SumExchangeOptions o;
  o.passes = -1;
  EXPECT_THROW(lower_error_sum(problem, spheres, 1.0, o), icd::ParameterError);
  o = {};
  o.cap_fraction = 0;
  EXPECT_THROW(lower_error_sum(problem, spheres, 1.0, o), icd::ParameterError);
}

}  // namespace
