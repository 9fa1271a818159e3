#include <gtest/gtest.h>

#include <random>

#include <icd/collision/broad_phase.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::collision {
namespace {

TEST(BroadPhase, SweepAndPruneEqualsAllPairs) {
  std::mt19937 rng(0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 1 + trial * 25;
    std::uniform_real_distribution<double> u(0, 10), ur(0, 0.2 + 0.1 * (trial % 5));
    std::vector<Sphere> s(n);
    for (Sphere& sp : s) sp = {u(rng), u(rng), u(rng), ur(rng)};
    if (n > 4) {  // exact touching and identical spheres
      s[1] = s[0];
      s[2] = {s[0].x + s[0].r + 0.5, s[0].y, s[0].z, 0.5};
      s[3] = {s[0].x, s[0].y, s[0].z, 0.0};
    }
    const auto expected = all_pairs_overlapping(s);
    EXPECT_EQ(sweep_and_prune(s), expected) << "trial " << trial;
    if (trial == 19) {
      EXPECT_GT(expected.size(), 50u);
    }
  }
  EXPECT_TRUE(sweep_and_prune({}).empty());
  EXPECT_THROW(sweep_and_prune({{0, 0, 0, 1}, {0, std::nan(""), 0, 1}}), ParameterError);
}

}  // namespace
}  // namespace icd::collision
