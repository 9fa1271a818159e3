// PointGrid ball and nearest queries against brute force.
#include <gtest/gtest.h>

#include <random>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/point_grid.hpp>

namespace {

using icd::mesh::PointGrid;

TEST(PointGrid, BallAndNearestMatchBruteForce) {
  std::mt19937 rng(0);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  icd::MatX3d P(2000, 3);
  for (Eigen::Index i = 0; i < P.rows(); ++i) P.row(i) << u(rng), 0.2 * u(rng), u(rng);
  // A cell size that needs coarsening (tiny cells) and a normal one.
  for (const double cell : {1e-4, 0.3}) {
    const PointGrid grid(P, cell);
    EXPECT_EQ(grid.size(), 2000);
    for (int t = 0; t < 200; ++t) {
      const Eigen::Vector3d c(2 * u(rng), u(rng), 2 * u(rng));  // also outside the points' box
      const double radius = t % 10 == 0 ? 20.0 : 0.1 * std::abs(u(rng));
      std::vector<int> brute;
      int nearest = -1;
      double best = 1e300;
      for (Eigen::Index i = 0; i < P.rows(); ++i) {
        const double d = (P.row(i).transpose() - c).norm();
        if (d <= radius) brute.push_back(int(i));
        if (d < best) best = d, nearest = int(i);
      }
      EXPECT_EQ(grid.query_ball(c, radius), brute) << "cell " << cell << " query " << t;
      EXPECT_EQ(grid.nearest(c), nearest);
    }
  }
}

TEST(PointGrid, NearestOfEquallyNearPointsIsTheLowestIndex) {
  // Point 0 lies in a cell the query scans after point 2's; 1 and 3 repeat them.
  icd::MatX3d P(4, 3);
  P << 1, 0, 0, 0, 5, 0, -1, 0, 0, 1, 0, 0;
  for (const double cell : {0.25, 1.0, 10.0}) {
    const PointGrid grid(P, cell);
    EXPECT_EQ(grid.nearest(Eigen::Vector3d::Zero()), 0) << "cell " << cell;
    EXPECT_EQ(grid.nearest(Eigen::Vector3d(-0.1, 0, 0)), 2) << "cell " << cell;
  }
}

TEST(PointGrid, EmptyAndInvalid) {
  const PointGrid empty(icd::MatX3d(0, 3), 1.0);
  EXPECT_TRUE(empty.query_ball(Eigen::Vector3d::Zero(), 5.0).empty());
  EXPECT_EQ(empty.nearest(Eigen::Vector3d::Zero()), -1);
  EXPECT_THROW(PointGrid(icd::MatX3d(1, 3), 0.0), icd::ParameterError);
  icd::MatX3d one(1, 3);
  one << 1, 2, 3;
  const PointGrid grid(one, 0.5);
  EXPECT_EQ(grid.nearest(Eigen::Vector3d(100, -50, 7)), 0);
  EXPECT_EQ(grid.query_ball(Eigen::Vector3d(1, 2, 3), 0.0), std::vector<int>{0});
}

}  // namespace
