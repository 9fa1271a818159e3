// reduce_to_spheres (split + Lloyd reduction of a node's samples to 1..k
// spheres) on box samples: every configuration partitions the samples,
// each sphere's radius is the brute-force smallest one covering its members
// with margin, and the result is the same, bit for bit, on 1 and 3 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/medial_axis.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/point_grid.hpp>
#include <icd/mesh/spheres/reduction.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

namespace {

using namespace icd::mesh;

TEST(Reduction, ConfigurationsPartitionTheSamplesAndDoNotDependOnTheThreadCount) {
  // A box: its samples' convex hulls are small (flat faces), so the fits are fast.
  const icd::SurfaceMesh box = icd::make_box_surface({0, 0, 0}, {2, 1, 1});
  const MeshOracle oracle(box);
  // Dense samples to divide; candidate centres from a coarser sampling.
  const SurfaceSamples samples = sample_surface(box.V, box.F, SamplingOptions{0.022});
  const SurfaceSamples coarse = sample_surface(box.V, box.F, SamplingOptions{0.1});
  const MedialSpheres medial = approximate_medial_axis(oracle, coarse, MedialAxisOptions{});
  const PointGrid grid(medial.centers, 0.2);
  const ReductionProblem problem{samples.points, samples.gap, medial, grid};
  std::vector<int> members(static_cast<size_t>(samples.points.rows()));
  for (size_t i = 0; i < members.size(); ++i) members[i] = static_cast<int>(i);
  // Blocks of the assignment hold 16384 members: more than one here.
  ASSERT_GT(members.size(), 20000u) << members.size();

  ReductionOptions options;
  const auto serial = reduce_to_spheres(problem, members, 6, options);
  options.threads = 3;
  const auto parallel = reduce_to_spheres(problem, members, 6, options);
  ASSERT_EQ(serial.size(), 6u);
  ASSERT_EQ(parallel.size(), serial.size());
  for (size_t k = 0; k < serial.size(); ++k) {
    ASSERT_EQ(parallel[k].size(), serial[k].size()) << "k " << k + 1;
    EXPECT_LE(serial[k].size(), k + 1);
    std::vector<int> all;
    for (size_t j = 0; j < serial[k].size(); ++j) {
      const FittedSphere &a = serial[k][j], &b = parallel[k][j];
      EXPECT_TRUE(a.center == b.center) << "k " << k + 1 << " sphere " << j;
      EXPECT_EQ(a.radius, b.radius);
      EXPECT_EQ(a.depth, b.depth);
      EXPECT_EQ(a.members, b.members);
      double radius = 0;
      for (int s : a.members) radius = std::max(radius, problem.reach(s, a.center));
      EXPECT_EQ(a.radius, radius) << "k " << k + 1 << " sphere " << j;
      EXPECT_NEAR(a.error, a.radius - a.depth, 1e-12);
      all.insert(all.end(), a.members.begin(), a.members.end());
    }
    std::sort(all.begin(), all.end());
    EXPECT_EQ(all, members) << "k " << k + 1 << ": not a partition of the samples";
  }
  // The split spheres are tighter than the one sphere around everything.
  double worst = 0;
  for (const FittedSphere& s : serial.back()) worst = std::max(worst, s.error);
  EXPECT_LT(worst, serial.front().front().error);

  options.threads = 0;
  EXPECT_THROW(reduce_to_spheres(problem, members, 2, options), icd::ParameterError);
}

}  // namespace
