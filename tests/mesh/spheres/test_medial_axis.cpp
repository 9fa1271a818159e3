// Medial-axis approximation against analytic medial radii of a box and a sphere.
#include <gtest/gtest.h>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/medial_axis.hpp>

namespace {

using namespace icd::mesh;

TEST(MedialAxis, BoxSpheresAreInsideWithExactDepth) {
  const Eigen::Vector3d lo(0, 0, 0), hi(2, 1, 1);
  const auto box = icd::make_box_surface(lo, hi);
  const MeshOracle oracle(box);
  const auto samples = sample_surface(box.V, box.F, SamplingOptions{0.1});
  const MedialSpheres medial = approximate_medial_axis(oracle, samples, MedialAxisOptions{});
  ASSERT_GT(medial.centers.rows(), 0);
  double deepest = 0;
  for (Eigen::Index i = 0; i < medial.centers.rows(); ++i) {
    const Eigen::Vector3d c = medial.centers.row(i);
    EXPECT_TRUE((c.array() >= lo.array() - 1e-12).all() && (c.array() <= hi.array() + 1e-12).all());
    const double analytic = std::min((c - lo).minCoeff(), (hi - c).minCoeff());
    EXPECT_NEAR(medial.radii[i], analytic, 1e-9);
    deepest = std::max(deepest, medial.radii[i]);
  }
  // The box's largest inscribed ball has radius 0.5; the samples find it closely.
  EXPECT_LE(deepest, 0.5 + 1e-9);
  EXPECT_GE(deepest, 0.45);
}

TEST(MedialAxis, SphereMedialAxisIsNearTheCentre) {
  const auto sphere = icd::make_icosphere(3);
  const MeshOracle oracle(sphere);
  const auto samples = sample_surface(sphere.V, sphere.F, SamplingOptions{0.1});
  MedialAxisOptions options;
  options.error_tolerance = 0.01;
  const MedialSpheres medial = approximate_medial_axis(oracle, samples, options);
  // The deepest Voronoi vertex approximates the centre; its depth approaches
  // the inradius of the polyhedron (<= 1).
  Eigen::Index best = 0;
  medial.radii.maxCoeff(&best);
  EXPECT_LT(medial.centers.row(best).norm(), 0.05);
  EXPECT_GT(medial.radii[best], 0.95);
  EXPECT_LE(medial.radii.maxCoeff(), 1.0);
  EXPECT_EQ(medial.centers.rows(), medial.radii.size());
  EXPECT_GE(medial.num_voronoi, 1);
}

TEST(MedialAxis, SameSpheresOnEveryNumberOfWorkers) {
  // A torus refined over two rounds (so that cells are classified again
  // after insertions): 1, 2 and 3 workers give the same spheres, bit for bit.
  const auto torus = icd::make_torus(1.0, 0.35, 24, 12);
  const MeshOracle a(torus), b(torus), c(torus);
  const auto samples = sample_surface(torus.V, torus.F, SamplingOptions{0.05});
  MedialAxisOptions options;
  options.error_tolerance = 0.005;
  const MedialSpheres one = approximate_medial_axis(a, samples, options);
  ASSERT_GT(one.num_inserted, 0);
  ASSERT_GT(one.num_voronoi, 100);
  for (const std::vector<const MeshOracle*>& oracles :
       {std::vector<const MeshOracle*>{&a, &b}, std::vector<const MeshOracle*>{&a, &b, &c}}) {
    const MedialSpheres many = approximate_medial_axis(oracles, samples, options);
    EXPECT_EQ(many.num_voronoi, one.num_voronoi);
    EXPECT_EQ(many.num_inserted, one.num_inserted);
    ASSERT_EQ(many.centers.rows(), one.centers.rows());
    EXPECT_TRUE(many.centers == one.centers);
    EXPECT_TRUE(many.radii == one.radii);
    EXPECT_TRUE(many.circumradii == one.circumradii);
  }
  EXPECT_THROW(approximate_medial_axis(std::vector<const MeshOracle*>{}, samples, options),
               icd::ParameterError);
  EXPECT_THROW(approximate_medial_axis(std::vector<const MeshOracle*>{&a, nullptr}, samples, options),
               icd::ParameterError);
}

TEST(MedialAxis, RejectsBadOptionsAndTooFewSamples) {
  const auto box = icd::make_box_surface({0, 0, 0}, {1, 1, 1});
  const MeshOracle oracle(box);
  const auto samples = sample_surface(box.V, box.F, SamplingOptions{0.5});
  MedialAxisOptions bad;
  bad.error_tolerance = 0;
  EXPECT_THROW(approximate_medial_axis(oracle, samples, bad), icd::ParameterError);
  bad = {};
  bad.refinement_iterations = -1;
  EXPECT_THROW(approximate_medial_axis(oracle, samples, bad), icd::ParameterError);
  SurfaceSamples few;
  few.points = samples.points.topRows(3);
  few.gap = samples.gap.head(3);
  few.face = samples.face.head(3);
  EXPECT_THROW(approximate_medial_axis(oracle, few, MedialAxisOptions{}), icd::InputError);
}

}  // namespace
