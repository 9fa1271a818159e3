// farthest_members (mesh/spheres/reduction.hpp: the support points the
// centre polish and the hull prefilter search on) against a scan of every
// member, the rule it replaces: for each direction the first member with
// the largest value, ties included.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/reduction.hpp>

namespace {

using icd::MatX3d;
using icd::mesh::farthest_members;

/// The reference: every member in order, "v > best" (the first maximum wins).
std::vector<int> scan_all(const MatX3d& points, const std::vector<int>& members,
                          const MatX3d& dirs) {
  std::vector<int> out;
  for (Eigen::Index d = 0; d < dirs.rows(); ++d) {
    double best = -std::numeric_limits<double>::infinity();
    int arg = members.front();
    for (int s : members) {
      const double v =
          dirs(d, 0) * points(s, 0) + dirs(d, 1) * points(s, 1) + dirs(d, 2) * points(s, 2);
      if (v > best) best = v, arg = s;
    }
    out.push_back(arg);
  }
  return out;
}

TEST(FarthestMembers, EqualsAScanOfEveryMemberTiesIncluded) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  MatX3d dirs = icd::make_icosphere(2, 1.0).V;
  const Eigen::Index n_ico = dirs.rows();
  dirs.conservativeResize(n_ico + 4, 3);
  dirs.row(n_ico) << 1, 0, 0;  // axis directions: zero components
  dirs.row(n_ico + 1) << 0, -1, 0;
  dirs.row(n_ico + 2) << 0.6, 0, -0.8;
  dirs.row(n_ico + 3) << -0.3, 0.2, 0.1;  // not unit: any direction
  for (int trial = 0; trial < 12; ++trial) {
    // Points on a few coarse lattice values, so that many share coordinates
    // and values tie; some exact duplicates; a spatially sorted half.
    const int n = trial < 3 ? 10 + 30 * trial : 500 + 700 * trial;
    MatX3d points(n, 3);
    for (int i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c)
        points(i, c) = trial % 2 == 0 ? std::round(8 * u(rng)) / 8 : u(rng);
    }
    for (int i = 0; i + 7 < n; i += 7) points.row(i + 7) = points.row(i);
    std::vector<int> members(static_cast<size_t>(n));
    std::iota(members.begin(), members.end(), 0);
    if (trial % 3 == 1) std::shuffle(members.begin(), members.end(), rng);
    if (trial % 3 == 2) {  // a subset, in sorted order
      std::vector<int> sub;
      for (int s : members)
        if (u(rng) > -0.2) sub.push_back(s);
      members = sub;
    }
    ASSERT_FALSE(members.empty());
    EXPECT_EQ(farthest_members(points, members, dirs), scan_all(points, members, dirs))
        << "trial " << trial << ", " << members.size() << " members";
  }
}

TEST(FarthestMembers, SizesAroundTheBlockAndEmpty) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-5, 5);
  const MatX3d dirs = icd::make_icosphere(1, 1.0).V;
  for (int n : {1, 2, 63, 64, 65, 128, 129}) {
    MatX3d points(n, 3);
    for (int i = 0; i < n; ++i) points.row(i) << u(rng), u(rng), u(rng);
    // All equal but the last: the first member wins every tie, the last only
    // where it is strictly farther.
    if (n > 2) points.topRows(n - 1).rowwise() = points.row(0);
    std::vector<int> members(static_cast<size_t>(n));
    std::iota(members.begin(), members.end(), 0);
    EXPECT_EQ(farthest_members(points, members, dirs), scan_all(points, members, dirs)) << n;
  }
  const MatX3d points = MatX3d::Zero(3, 3);
  EXPECT_EQ(farthest_members(points, {}, dirs),
            std::vector<int>(static_cast<size_t>(dirs.rows()), -1));
}

}  // namespace
