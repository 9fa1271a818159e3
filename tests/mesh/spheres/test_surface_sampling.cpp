// Surface sampling: the coverage-margin guarantee (every surface point within
// gap of some sample) against brute force on independent random points, and
// the area bookkeeping against closed-form areas.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

namespace {

using icd::mesh::sample_surface;
using icd::mesh::SamplingOptions;

/// Uniform random point on triangle f of (V, F).
Eigen::Vector3d random_point(const icd::SurfaceMesh& m, int f, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  double a = u(rng), b = u(rng);
  if (a + b > 1) a = 1 - a, b = 1 - b;
  const Eigen::Vector3d p0 = m.V.row(m.F(f, 0)), p1 = m.V.row(m.F(f, 1)), p2 = m.V.row(m.F(f, 2));
  return p0 + a * (p1 - p0) + b * (p2 - p0);
}

void expect_gap_guarantee(const icd::SurfaceMesh& mesh, double spacing) {
  const auto samples = sample_surface(mesh.V, mesh.F, SamplingOptions{spacing});
  std::mt19937 rng(0);
  std::uniform_int_distribution<int> face(0, static_cast<int>(mesh.F.rows()) - 1);
  for (int t = 0; t < 400; ++t) {
    const Eigen::Vector3d p = random_point(mesh, face(rng), rng);
    bool ok = false;
    for (Eigen::Index s = 0; s < samples.points.rows() && !ok; ++s) {
      ok = (samples.points.row(s).transpose() - p).norm() <= samples.gap[s] + 1e-12;
    }
    EXPECT_TRUE(ok) << "random point " << t << " is farther than the gap from every sample";
  }
  EXPECT_LE(samples.gap.maxCoeff(), spacing / std::sqrt(3.0) + 1e-12);
}

TEST(SurfaceSampling, EverySurfacePointIsWithinTheGapOfASample) {
  expect_gap_guarantee(icd::make_torus(1.0, 0.3, 12, 8), 0.15);
  expect_gap_guarantee(icd::make_box_surface({0, 0, 0}, {2, 1, 0.5}), 0.3);
  expect_gap_guarantee(icd::make_icosphere(1), 0.2);
}

TEST(SurfaceSampling, AreasSumToTheClosedFormArea) {
  const auto box = icd::make_box_surface({0, 0, 0}, {2, 1, 0.5});
  const auto samples = sample_surface(box.V, box.F, SamplingOptions{0.1});
  EXPECT_NEAR(samples.area.sum(), 2 * (2 * 1 + 2 * 0.5 + 1 * 0.5), 1e-9);
  EXPECT_NEAR(icd::mesh::surface_area(box.V, box.F), 7.0, 1e-12);
  EXPECT_GT(samples.area.minCoeff(), 0.0);
}

TEST(SurfaceSampling, VerticesComeFirstAndOutputIsDeterministic) {
  const auto torus = icd::make_torus(1.0, 0.3, 12, 8);
  const auto a = sample_surface(torus.V, torus.F, SamplingOptions{0.1});
  const auto b = sample_surface(torus.V, torus.F, SamplingOptions{0.1});
  ASSERT_EQ(a.num_vertex_samples, torus.V.rows());
  EXPECT_TRUE(a.points.topRows(torus.V.rows()).isApprox(torus.V));
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.gap, b.gap);
  // Finer spacing gives more samples, roughly with the inverse square.
  const auto fine = sample_surface(torus.V, torus.F, SamplingOptions{0.05});
  EXPECT_GT(fine.points.rows(), 3 * (a.points.rows() - torus.V.rows()));
}

// A slab of long thin faces (gear teeth, CAD fans): the lattice would put
// (L / spacing)^2 / 2 needles on each long triangle whatever its area; the
// column sampling keeps the count near area / spacing^2 plus the edges'
// lengths / spacing, with the same coverage guarantee and area bookkeeping.
TEST(SurfaceSampling, ThinTrianglesAreSampledByAreaWithTheSameGuarantee) {
  const Eigen::Vector3d hi(40, 1, 0.05);
  const auto slab = icd::make_box_surface({0, 0, 0}, hi);
  const double spacing = 0.25;
  expect_gap_guarantee(slab, spacing);
  const auto samples = sample_surface(slab.V, slab.F, SamplingOptions{spacing});
  const double area = 2 * (hi.x() * hi.y() + hi.x() * hi.z() + hi.y() * hi.z());
  EXPECT_NEAR(samples.area.sum(), area, 1e-9 * area);
  EXPECT_GE(samples.area.minCoeff(), 0.0);
  double lattice = 0, edges = 0;  // what the n x n lattice would give; longest edges
  for (Eigen::Index f = 0; f < slab.F.rows(); ++f) {
    const Eigen::Vector3d a = slab.V.row(slab.F(f, 0)), b = slab.V.row(slab.F(f, 1)),
                          c = slab.V.row(slab.F(f, 2));
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const double n = std::max(1.0, std::ceil(longest / spacing));
    lattice += (n + 1) * (n + 2) / 2 - 3;
    edges += longest / spacing;
  }
  const double bound = 3 * (area / (spacing * spacing) + edges);
  EXPECT_LT(static_cast<double>(samples.points.rows()), bound);
  EXPECT_GT(lattice, 4 * bound);  // the lattice would not meet it
  for (Eigen::Index s = 0; s < samples.points.rows(); ++s) {
    ASSERT_GE(samples.face[s], 0);
    // Every sample lies on its face's plane and within its bounding box.
    const Eigen::Vector3d a = slab.V.row(slab.F(samples.face[s], 0)),
                          b = slab.V.row(slab.F(samples.face[s], 1)),
                          c = slab.V.row(slab.F(samples.face[s], 2));
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    EXPECT_NEAR(n.dot(samples.points.row(s).transpose() - a), 0.0, 1e-9);
  }
}

// Well-shaped triangles keep the n x n lattice: the count is the lattice's.
TEST(SurfaceSampling, WellShapedTrianglesKeepTheLattice) {
  const auto sphere = icd::make_icosphere(2);
  const double spacing = 0.05;
  const auto samples = sample_surface(sphere.V, sphere.F, SamplingOptions{spacing});
  long long expected = sphere.V.rows();
  for (Eigen::Index f = 0; f < sphere.F.rows(); ++f) {
    const Eigen::Vector3d a = sphere.V.row(sphere.F(f, 0)), b = sphere.V.row(sphere.F(f, 1)),
                          c = sphere.V.row(sphere.F(f, 2));
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const long long n = std::max(1LL, static_cast<long long>(std::ceil(longest / spacing)));
    expected += (n + 1) * (n + 2) / 2 - 3;
  }
  EXPECT_EQ(samples.points.rows(), expected);
}

TEST(SurfaceSampling, RejectsBadInput) {
  const auto box = icd::make_box_surface({0, 0, 0}, {1, 1, 1});
  EXPECT_THROW(sample_surface(box.V, box.F, SamplingOptions{0.0}), icd::ParameterError);
  EXPECT_THROW(sample_surface(box.V, box.F, SamplingOptions{std::nan("")}), icd::ParameterError);
  EXPECT_THROW(sample_surface(box.V, box.F, SamplingOptions{0.5, 0.5}), icd::ParameterError);
  icd::SurfaceMesh bad = box;
  bad.F(3, 1) = 99;
  EXPECT_THROW(sample_surface(bad.V, bad.F, SamplingOptions{0.5}), icd::InputError);
  bad = box;
  bad.V(2, 0) = std::nan("");
  EXPECT_THROW(sample_surface(bad.V, bad.F, SamplingOptions{0.5}), icd::InputError);
}

}  // namespace
