// Merge/burst reduction on small meshes (sphere, box, torus): every
// configuration partitions the samples and covers each with its margin, the
// error bound is radius - depth, and the quality is checked against
// hand-built configurations evaluated by brute force (one ball for the
// sphere, spheres on the ring for the torus).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/medial_axis.hpp>
#include <icd/mesh/spheres/merge_burst.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

namespace {

using namespace icd::mesh;

/// Everything a reduction needs, built from a closed mesh.
struct ReductionSetup {
  explicit ReductionSetup(const icd::SurfaceMesh& mesh, double spacing)
      : oracle(mesh),
        samples(sample_surface(mesh.V, mesh.F, SamplingOptions{spacing})),
        medial(approximate_medial_axis(oracle, samples, MedialAxisOptions{})),
        grid(medial.centers, spacing),
        problem{samples.points, samples.gap, medial, grid} {}
  MeshOracle oracle;
  SurfaceSamples samples;
  MedialSpheres medial;
  PointGrid grid;
  ReductionProblem problem;

  std::vector<int> all() const {
    std::vector<int> m(static_cast<size_t>(samples.points.rows()));
    std::iota(m.begin(), m.end(), 0);
    return m;
  }
  std::vector<std::vector<FittedSphere>> reduce(int max_k, double spacing) const {
    MergeBurstOptions o;
    o.neighbour_radius = 1.5 * spacing;
    return merge_burst_reduce(problem, medial_owners(problem, spacing), all(), max_k,
                              ReductionOptions{}, o);
  }
};

double worst_error(const std::vector<FittedSphere>& config) {
  double w = 0;
  for (const auto& s : config) w = std::max(w, s.error);
  return w;
}

void expect_valid(const ReductionSetup& setup,
                  const std::vector<std::vector<FittedSphere>>& configs, int max_k) {
  ASSERT_EQ(static_cast<int>(configs.size()), max_k);
  const auto& P = setup.samples.points;
  for (int k = 1; k <= max_k; ++k) {
    SCOPED_TRACE("k = " + std::to_string(k));
    const auto& config = configs[static_cast<size_t>(k - 1)];
    ASSERT_FALSE(config.empty());
    EXPECT_LE(static_cast<int>(config.size()), k);
    std::vector<int> joined;
    for (const auto& s : config) {
      EXPECT_FALSE(s.members.empty());
      EXPECT_NEAR(s.error, s.radius - s.depth, 1e-12);
      // The depth is the centre's distance to the surface (the centre is inside).
      EXPECT_TRUE(setup.oracle.inside(s.center));
      EXPECT_NEAR(s.depth, setup.oracle.distance(s.center), 1e-9);
      for (int m : s.members) {
        EXPECT_LE((P.row(m).transpose() - s.center).norm() + setup.samples.gap[m],
                  s.radius * (1 + 1e-12));
      }
      joined.insert(joined.end(), s.members.begin(), s.members.end());
    }
    std::sort(joined.begin(), joined.end());
    EXPECT_EQ(joined, setup.all()) << "each sample in exactly one sphere";
  }
}

TEST(MergeBurst, SphereReducesToOneBallAtTheCentre) {
  const auto mesh = icd::make_icosphere(2);
  const ReductionSetup setup(mesh, 0.15);
  const auto configs = setup.reduce(4, 0.15);
  expect_valid(setup, configs, 4);
  // Oracle: the ball at the origin covering every sample with margin; its
  // error bound is that radius minus the polyhedron's inradius.
  double r = 0;
  for (Eigen::Index s = 0; s < setup.samples.points.rows(); ++s) {
    r = std::max(r, setup.samples.points.row(s).norm() + setup.samples.gap[s]);
  }
  const double hand = r - setup.oracle.distance(Eigen::Vector3d::Zero());
  EXPECT_LE(worst_error(configs[0]), hand + 0.05);
  EXPECT_LE(configs[0].front().center.norm(), 0.1);
}

TEST(MergeBurst, TorusBeatsSpheresPlacedOnTheRing) {
  const double R = 1.0, a = 0.3;
  const auto mesh = icd::make_torus(R, a, 32, 12);
  const ReductionSetup setup(mesh, 0.08);
  const int k = 8;
  const auto configs = setup.reduce(k, 0.08);
  expect_valid(setup, configs, k);
  // Oracle: k spheres on the ring, each covering the samples of its 360/k
  // degree sector with margin (brute force); error bound radius - depth.
  double hand = 0;
  for (int j = 0; j < k; ++j) {
    const double phi = 2 * M_PI * (j + 0.5) / k;
    const Eigen::Vector3d c(R * std::cos(phi), R * std::sin(phi), 0);
    double r = 0;
    for (Eigen::Index s = 0; s < setup.samples.points.rows(); ++s) {
      const Eigen::Vector3d p = setup.samples.points.row(s);
      double angle = std::atan2(p.y(), p.x());
      if (angle < 0) angle += 2 * M_PI;
      if (static_cast<int>(std::floor(angle / (2 * M_PI) * k)) % k != j) continue;
      r = std::max(r, (p - c).norm() + setup.samples.gap[s]);
    }
    hand = std::max(hand, r - setup.oracle.distance(c));
  }
  EXPECT_LE(worst_error(configs[static_cast<size_t>(k - 1)]), 1.2 * hand);
  // And one sphere for the whole torus is far worse than eight.
  EXPECT_GT(worst_error(configs[0]), 2 * worst_error(configs[static_cast<size_t>(k - 1)]));
}

TEST(MergeBurst, BoxConfigurationsAreValidAndDeterministic) {
  const auto mesh = icd::make_box_surface({0, 0, 0}, {2, 1, 0.6});
  const ReductionSetup setup(mesh, 0.12);
  const auto a = setup.reduce(6, 0.12);
  expect_valid(setup, a, 6);
  const auto b = setup.reduce(6, 0.12);
  for (size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].size(), b[k].size());
    for (size_t i = 0; i < a[k].size(); ++i) {
      EXPECT_EQ(a[k][i].center, b[k][i].center);
      EXPECT_EQ(a[k][i].radius, b[k][i].radius);
      EXPECT_EQ(a[k][i].members, b[k][i].members);
    }
  }
  // A 2 x 1 x 0.6 slab: one sphere protrudes by about its half-diagonal minus
  // 0.3; six spheres along the long side do much better.
  EXPECT_LT(worst_error(a[5]), 0.5 * worst_error(a[0]));
}

TEST(MergeBurst, RejectsBadArguments) {
  const auto mesh = icd::make_box_surface({0, 0, 0}, {1, 1, 1});
  const ReductionSetup setup(mesh, 0.2);
  const auto owners = medial_owners(setup.problem, 0.2);
  EXPECT_THROW(medial_owners(setup.problem, 0.0), icd::ParameterError);
  MergeBurstOptions o;
  EXPECT_THROW(merge_burst_reduce(setup.problem, owners, setup.all(), 0, ReductionOptions{}, o),
               icd::ParameterError);
  EXPECT_THROW(merge_burst_reduce(setup.problem, owners, {}, 2, ReductionOptions{}, o),
               icd::ParameterError);
  EXPECT_THROW(merge_burst_reduce(setup.problem, {0, 1}, setup.all(), 2, ReductionOptions{}, o),
               icd::ParameterError);
  o.neighbour_radius = -1;
  EXPECT_THROW(merge_burst_reduce(setup.problem, owners, setup.all(), 2, ReductionOptions{}, o),
               icd::ParameterError);
}

}  // namespace
