// Boundary exchange between spheres (shrink_by_exchange, relieve_worst):
// checked by brute force on the samples of a torus (coverage with margin
// kept, no radius grows / the worst error drops, members partitioned, the
// receiver predicate respected) and on samples along a line, where the
// result is known in closed form or by enumerating every split.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/exchange.hpp>
#include <icd/mesh/spheres/medial_axis.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

namespace {

using namespace icd::mesh;

/// Spheres around random centres, each covering the samples nearest to it
/// with margin (a valid but poor configuration).
std::vector<FittedSphere> nearest_centre_spheres(const icd::MatX3d& P, const Eigen::VectorXd& gap,
                                                 int k, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Eigen::Index> pick(0, P.rows() - 1);
  std::vector<FittedSphere> spheres(static_cast<size_t>(k));
  for (auto& s : spheres) s.center = P.row(pick(rng)).transpose() * 0.9;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    size_t best = 0;
    for (size_t j = 1; j < spheres.size(); ++j) {
      if ((P.row(i).transpose() - spheres[j].center).norm() <
          (P.row(i).transpose() - spheres[best].center).norm()) {
        best = j;
      }
    }
    spheres[best].members.push_back(static_cast<int>(i));
  }
  for (auto& s : spheres) {
    for (int m : s.members)
      s.radius = std::max(s.radius, (P.row(m).transpose() - s.center).norm() + gap[m]);
    s.depth = 0.1;
    s.error = s.radius - s.depth;
  }
  return spheres;
}

TEST(Exchange, KeepsCoverageAndNeverGrowsARadius) {
  const auto torus = icd::make_torus(1.0, 0.3, 24, 12);
  const auto samples = sample_surface(torus.V, torus.F, SamplingOptions{0.05});
  const MedialSpheres medial;  // unused by the exchange
  const PointGrid grid(samples.points, 0.5);
  const ReductionProblem problem{samples.points, samples.gap, medial, grid};
  std::vector<FittedSphere> spheres = nearest_centre_spheres(samples.points, samples.gap, 12, 3);
  // Inflate some spheres so that they overlap their neighbours a lot.
  for (size_t j = 0; j < spheres.size(); j += 3)
    spheres[j].radius *= 1.5, spheres[j].error = spheres[j].radius - 0.1;
  const auto before = spheres;
  // Receivers with an even index only.
  const int moved = shrink_by_exchange(problem, spheres, ExchangeOptions{},
                                       [](int k, int) { return k % 2 == 0; });
  EXPECT_GT(moved, 0);
  std::vector<int> joined;
  double sum_before = 0, sum_after = 0;
  for (size_t j = 0; j < spheres.size(); ++j) {
    const auto& s = spheres[j];
    EXPECT_LE(s.radius, before[j].radius);
    EXPECT_EQ(s.center, before[j].center);
    EXPECT_NEAR(s.error, s.radius - s.depth, 1e-12);
    EXPECT_FALSE(s.members.empty());
    EXPECT_TRUE(std::is_sorted(s.members.begin(), s.members.end()));
    double r = 0;
    for (int m : s.members)
      r = std::max(r, (samples.points.row(m).transpose() - s.center).norm() + samples.gap[m]);
    EXPECT_LE(r, s.radius) << "sphere " << j << " lost coverage of a member";
    // Odd spheres received nothing: their members are a subset of their old ones.
    if (j % 2 == 1) {
      EXPECT_TRUE(std::includes(before[j].members.begin(), before[j].members.end(),
                                s.members.begin(), s.members.end()));
    }
    joined.insert(joined.end(), s.members.begin(), s.members.end());
    sum_before += before[j].error, sum_after += s.error;
  }
  std::sort(joined.begin(), joined.end());
  std::vector<int> all(static_cast<size_t>(samples.points.rows()));
  std::iota(all.begin(), all.end(), 0);
  EXPECT_EQ(joined, all);
  EXPECT_LT(sum_after, sum_before);
}

TEST(Exchange, HandsTheFarthestSampleToTheNeighbourThatCoversIt) {
  // Samples at x = 0..10 (gap 0). A at 0 owns 0..6 (radius 6), B at 8 owns
  // 7..10 (radius 2). A goes first (larger error): its farthest sample 6 is
  // within B (|6 - 8| = 2), sample 5 is not, so A shrinks to radius 5; B
  // cannot give 6 or 10 back (outside A's new radius) and keeps radius 2.
  icd::MatX3d P(11, 3);
  for (int i = 0; i <= 10; ++i) P.row(i) << i, 0, 0;
  const Eigen::VectorXd gap = Eigen::VectorXd::Zero(11);
  const MedialSpheres medial;
  const PointGrid grid(P, 1.0);
  const ReductionProblem problem{P, gap, medial, grid};
  FittedSphere a, b;
  a.center = Eigen::Vector3d::Zero(), a.radius = 6, a.error = 6, a.members = {0, 1, 2, 3, 4, 5, 6};
  b.center = Eigen::Vector3d(8, 0, 0), b.radius = 2, b.error = 2, b.members = {7, 8, 9, 10};
  std::vector<FittedSphere> spheres{a, b};
  EXPECT_EQ(shrink_by_exchange(problem, spheres), 1);
  EXPECT_DOUBLE_EQ(spheres[0].radius, 5.0);
  EXPECT_DOUBLE_EQ(spheres[1].radius, 2.0);
  EXPECT_EQ(spheres[0].members, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(spheres[1].members, (std::vector<int>{6, 7, 8, 9, 10}));
}

TEST(Exchange, RelieveWorstReachesTheMinimaxSplitOnALine) {
  // Samples at x = 0..10 (gap 0), centres fixed at 0 and 8 (depth 0). The
  // best split for the worst radius is A = {0..4} (4), B = {5..10} (3), or
  // A = {0..3} (3), B = {4..10} (4): worst 4 (brute force over the 12 splits).
  icd::MatX3d P(11, 3);
  for (int i = 0; i <= 10; ++i) P.row(i) << i, 0, 0;
  const Eigen::VectorXd gap = Eigen::VectorXd::Zero(11);
  const MedialSpheres medial;
  const PointGrid grid(P, 1.0);
  const ReductionProblem problem{P, gap, medial, grid};
  double minimax = 1e9;
  for (int split = 0; split <= 11; ++split) {  // A = {0 .. split - 1}
    const double ra = split > 0 ? split - 1.0 : 0.0;
    const double rb = split <= 10 ? std::max(8.0 - split, 2.0) : 0.0;
    minimax = std::min(minimax, std::max(ra, rb));
  }
  FittedSphere a, b;  // A starts with 0..9, B with sample 10 only
  a.center = Eigen::Vector3d::Zero(), a.radius = 9, a.error = 9,
  a.members = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  b.center = Eigen::Vector3d(8, 0, 0), b.radius = 2, b.error = 2, b.members = {10};
  std::vector<FittedSphere> spheres{a, b};
  EXPECT_GT(relieve_worst(problem, spheres, 1000), 0);
  EXPECT_DOUBLE_EQ(std::max(spheres[0].error, spheres[1].error), minimax);
  std::vector<int> joined = spheres[0].members;
  joined.insert(joined.end(), spheres[1].members.begin(), spheres[1].members.end());
  std::sort(joined.begin(), joined.end());
  EXPECT_EQ(joined, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
  for (const auto& s : spheres) {
    for (int m : s.members) EXPECT_LE(std::abs(P(m, 0) - s.center.x()), s.radius);
  }
}

TEST(Exchange, RelieveWorstNeverRaisesTheWorstAndKeepsCoverage) {
  const auto torus = icd::make_torus(1.0, 0.3, 24, 12);
  const auto samples = sample_surface(torus.V, torus.F, SamplingOptions{0.05});
  const MedialSpheres medial;
  const PointGrid grid(samples.points, 0.5);
  const ReductionProblem problem{samples.points, samples.gap, medial, grid};
  std::vector<FittedSphere> spheres = nearest_centre_spheres(samples.points, samples.gap, 10, 5);
  // Make sphere 1 the worst: it takes every sample of sphere 2 but one.
  auto& taker = spheres[1];
  auto& giver = spheres[2];
  taker.members.insert(taker.members.end(), giver.members.begin() + 1, giver.members.end());
  std::sort(taker.members.begin(), taker.members.end());
  giver.members.resize(1);
  for (auto* sp : {&taker, &giver}) {
    sp->radius = 0;
    for (int m : sp->members) {
      sp->radius = std::max(
          sp->radius, (samples.points.row(m).transpose() - sp->center).norm() + samples.gap[m]);
    }
    sp->error = sp->radius - sp->depth;
  }
  double worst_before = 0;
  for (const auto& s : spheres) worst_before = std::max(worst_before, s.error);
  // Sphere 0 may receive nothing.
  relieve_worst(problem, spheres, 100000, [](int k, int) { return k != 0; });
  double worst_after = 0;
  std::vector<int> joined;
  for (const auto& s : spheres) {
    worst_after = std::max(worst_after, s.error);
    EXPECT_FALSE(s.members.empty());
    for (int m : s.members) {
      EXPECT_LE((samples.points.row(m).transpose() - s.center).norm() + samples.gap[m],
                s.radius * (1 + 1e-12));
    }
    joined.insert(joined.end(), s.members.begin(), s.members.end());
  }
  EXPECT_LT(worst_after, worst_before);
  std::sort(joined.begin(), joined.end());
  EXPECT_EQ(static_cast<Eigen::Index>(joined.size()), samples.points.rows());
  EXPECT_TRUE(std::adjacent_find(joined.begin(), joined.end()) == joined.end());
}

TEST(Exchange, RejectsBadOptions) {
  icd::MatX3d P(1, 3);
  P << 0, 0, 0;
  const Eigen::VectorXd gap = Eigen::VectorXd::Zero(1);
  const MedialSpheres medial;
  const PointGrid grid(P, 1.0);
  const ReductionProblem problem{P, gap, medial, grid};
  std::vector<FittedSphere> spheres(1);
  ExchangeOptions o;
  o.rounds = -1;
  EXPECT_THROW(shrink_by_exchange(problem, spheres, o), icd::ParameterError);
  EXPECT_THROW(relieve_worst(problem, spheres, -1), icd::ParameterError);
}

}  // namespace
