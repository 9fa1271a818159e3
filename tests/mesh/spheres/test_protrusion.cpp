// True sphere error (protrusion) and the centre polish that lowers it:
// spiral directions checked by brute force, the protrusion against the
// closed-form distance to a box, and the polish on box, torus and sphere
// samples against brute-force recomputation (every member still covered with
// margin, the radius the exact smallest one, the measured protrusion never
// higher, and lower overall).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/medial_axis.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/point_grid.hpp>
#include <icd/mesh/spheres/protrusion.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

namespace {

using namespace icd::mesh;

/// Exact distance from p to the box [lo, hi] (0 inside).
double box_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                    const Eigen::Vector3d& hi) {
  return (lo - p).cwiseMax(p - hi).cwiseMax(Eigen::Vector3d::Zero()).norm();
}

TEST(Protrusion, CoverRadiusEqualsTheLargestReachOverAllMembers) {
  // Two member sets, each evaluated from centres that move around as the
  // polish moves them; every value must equal the brute-force maximum
  // exactly. (a) A cap of the unit sphere (x > 0.5) and a whole sphere of
  // radius 1 - 3w inside it (w: the width of CoverRadius' bands): seen from
  // the origin, bands 1 and 2 are empty, and once the centre moves by more
  // than 2w towards the cap the farthest member is on the inner sphere,
  // three bands down. (b) Three shells (radii 1, 0.97, 0.6), random walks
  // with steps of three sizes, narrowing half-way.
  std::mt19937 rng(17);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto random_unit = [&] {
    return Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  };
  MedialSpheres medial;
  medial.centers = icd::MatX3d::Zero(1, 3);
  medial.radii = Eigen::VectorXd::Ones(1);
  medial.circumradii = medial.radii;
  const PointGrid grid(medial.centers, 1.0);
  auto check = [&](const icd::MatX3d& points, const Eigen::VectorXd& gap, double reach,
                   const std::vector<Eigen::Vector3d>& centres, int narrow_at) {
    const ReductionProblem problem{points, gap, medial, grid};
    std::vector<int> members(static_cast<size_t>(points.rows()));
    for (size_t i = 0; i < members.size(); ++i) members[i] = static_cast<int>(i);
    CoverRadius cover(problem, members, reach);
    for (size_t k = 0; k < centres.size(); ++k) {
      if (static_cast<int>(k) == narrow_at) cover.narrow(centres[k], reach / 2);
      double brute = 0;
      for (int s : members) brute = std::max(brute, problem.reach(s, centres[k]));
      ASSERT_EQ(cover(centres[k]), brute) << "reach " << reach << ", centre " << k;
    }
  };
  {
    const double reach = 0.04, w = 2 * reach / 8;
    icd::MatX3d points(2000, 3);
    Eigen::VectorXd gap(2000);
    for (int i = 0; i < 2000; ++i) {
      Eigen::Vector3d d = random_unit();
      if (i < 500) {
        while (d.x() <= 0.5) d = random_unit();
        points.row(i) = d.transpose();
      } else {
        points.row(i) = (1 - 3 * w) * d.transpose();
      }
      gap[i] = 1e-4 * unit(rng);
    }
    std::vector<Eigen::Vector3d> centres{Eigen::Vector3d::Zero()};
    for (int k = 1; k <= 40; ++k) centres.push_back(Eigen::Vector3d(reach * k / 41.0, 0, 0));
    for (int k = 0; k < 100; ++k) centres.push_back(reach * unit(rng) * random_unit());
    check(points, gap, reach, centres, -1);
  }
  {
    const int n = 3000;
    icd::MatX3d points(n, 3);
    Eigen::VectorXd gap(n);
    for (int i = 0; i < n; ++i) {
      const double radius = i % 3 == 0 ? 1.0 : i % 3 == 1 ? 0.97 : 0.6;
      points.row(i) = radius * random_unit().transpose();
      gap[i] = 0.01 * unit(rng);
    }
    for (double step : {0.2, 0.02, 0.002}) {
      std::vector<Eigen::Vector3d> centres;
      Eigen::Vector3d c(0.1, -0.05, 0.02);
      for (int k = 0; k < 300; ++k) centres.push_back(c += step * unit(rng) * random_unit());
      check(points, gap, 2 * step, centres, 150);
    }
  }
  const icd::MatX3d none(0, 3);
  const Eigen::VectorXd no_gap(0);
  const ReductionProblem empty{none, no_gap, medial, grid};
  EXPECT_THROW(CoverRadius(empty, {}, 1.0), icd::ParameterError);
  const std::vector<int> one{0};
  EXPECT_THROW(CoverRadius(empty, one, -1.0), icd::ParameterError);
}

TEST(Protrusion, SpiralDirectionsAreUnitAndCoverTheSphere) {
  EXPECT_THROW(spiral_directions(0), icd::ParameterError);
  const int n = 256;
  const icd::MatX3d D = spiral_directions(n);
  ASSERT_EQ(D.rows(), n);
  for (Eigen::Index i = 0; i < n; ++i) EXPECT_NEAR(D.row(i).norm(), 1.0, 1e-12);
  // Covering angle: every random direction is within ~1.5x the mean spacing
  // sqrt(4 pi / n) of a spiral direction (brute force over 20000 directions).
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0, 1);
  double worst = 0;
  for (int t = 0; t < 20000; ++t) {
    const Eigen::Vector3d u = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    double best = -1;
    for (Eigen::Index i = 0; i < n; ++i) best = std::max(best, D.row(i).dot(u));
    worst = std::max(worst, std::acos(std::min(1.0, best)));
  }
  EXPECT_LT(worst, 1.5 * std::sqrt(4 * M_PI / n));
  // Balanced: the mean direction is near zero.
  EXPECT_LT(D.colwise().mean().norm(), 0.01);
}

TEST(Protrusion, MatchesTheBoxDistance) {
  const Eigen::Vector3d lo(0, 0, 0), hi(2, 1, 0.6);
  const MeshOracle oracle(icd::make_box_surface(lo, hi));
  const icd::MatX3d D = spiral_directions(500);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.3, 1.3);
  for (int t = 0; t < 20; ++t) {
    const Eigen::Vector3d c(2 * u(rng), u(rng), 0.6 * u(rng));
    const double r = 0.05 + 0.4 * (u(rng) + 0.3);
    double expected = 0;
    for (Eigen::Index d = 0; d < D.rows(); ++d)
      expected = std::max(expected, box_distance(c + r * D.row(d).transpose(), lo, hi));
    EXPECT_NEAR(sphere_protrusion(oracle, c, r, D), expected, 1e-9) << "trial " << t;
  }
  // A sphere inside the box does not protrude.
  EXPECT_EQ(sphere_protrusion(oracle, Eigen::Vector3d(1, 0.5, 0.3), 0.2, D), 0.0);
}

struct Shape {
  std::string name;
  icd::SurfaceMesh mesh;
  double spacing;
};

/// Spheres around random sample points pulled towards the centroid, each
/// covering with margin the samples nearest to it (a valid, poor start).
std::vector<FittedSphere> start_spheres(const SurfaceSamples& s, int k, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Eigen::Index> pick(0, s.points.rows() - 1);
  const Eigen::Vector3d centroid = s.points.colwise().mean().transpose();
  std::vector<FittedSphere> spheres(static_cast<size_t>(k));
  for (auto& sp : spheres) {
    const Eigen::Vector3d p = s.points.row(pick(rng)).transpose();
    sp.center = centroid + 0.85 * (p - centroid);
  }
  for (Eigen::Index i = 0; i < s.points.rows(); ++i) {
    size_t best = 0;
    for (size_t j = 1; j < spheres.size(); ++j) {
      if ((s.points.row(i).transpose() - spheres[j].center).norm() <
          (s.points.row(i).transpose() - spheres[best].center).norm())
        best = j;
    }
    spheres[best].members.push_back(static_cast<int>(i));
  }
  for (auto& sp : spheres) {
    for (int m : sp.members)
      sp.radius = std::max(sp.radius, (s.points.row(m).transpose() - sp.center).norm() + s.gap[m]);
    sp.error = sp.radius;
  }
  return spheres;
}

TEST(Protrusion, PolishKeepsCoverageAndNeverRaisesTheMeasuredError) {
  const std::vector<Shape> shapes = {{"icosphere", icd::make_icosphere(3), 0.05},
                                     {"box", icd::make_box_surface({0, 0, 0}, {2, 1, 0.6}), 0.05},
                                     {"torus", icd::make_torus(1.0, 0.3, 32, 16), 0.05}};
  const ProtrusionPolishOptions options;
  const icd::MatX3d check = spiral_directions(options.check_directions);
  for (const auto& shape : shapes) {
    SCOPED_TRACE(shape.name);
    const MeshOracle oracle(shape.mesh);
    const SurfaceSamples samples =
        sample_surface(shape.mesh.V, shape.mesh.F, SamplingOptions{shape.spacing});
    const MedialSpheres medial;  // unused by the polish
    const PointGrid grid(samples.points, 0.5);
    const ReductionProblem problem{samples.points, samples.gap, medial, grid};
    std::vector<FittedSphere> spheres = start_spheres(samples, 10, 17);
    double sum_before = 0, sum_after = 0;
    int moved = 0;
    for (size_t j = 0; j < spheres.size(); ++j) {
      FittedSphere sp = spheres[j];
      if (sp.members.empty()) continue;
      const double before = sphere_protrusion(oracle, sp.center, sp.radius, check);
      const ProtrusionPolishResult r = polish_protrusion(problem, oracle, sp, 100 + j, options);
      EXPECT_EQ(sp.members, spheres[j].members);
      // Brute force: the exact smallest radius covering every member with margin.
      double radius = 0;
      for (int m : sp.members)
        radius = std::max(radius,
                          (samples.points.row(m).transpose() - sp.center).norm() + samples.gap[m]);
      EXPECT_NEAR(sp.radius, radius, 1e-12 * (1 + radius)) << "sphere " << j;
      const double after = sphere_protrusion(oracle, sp.center, sp.radius, check);
      if (r.checked) {
        EXPECT_NEAR(r.before, before, 1e-12);
        EXPECT_NEAR(r.after, after, 1e-12);
      }
      EXPECT_TRUE(r.checked || !r.moved);
      EXPECT_LE(after, before) << "sphere " << j;
      EXPECT_EQ(r.moved, sp.center != spheres[j].center);
      const double depth = oracle.inside(sp.center) ? oracle.distance(sp.center) : 0.0;
      EXPECT_NEAR(sp.depth, depth, 1e-12);
      EXPECT_NEAR(sp.error, sp.radius - sp.depth, 1e-12);
      sum_before += before, sum_after += after, moved += r.moved ? 1 : 0;
    }
    EXPECT_GT(moved, 0);
    EXPECT_LT(sum_after, 0.97 * sum_before);
  }
}

TEST(Protrusion, PolishIsDeterministicAndChecksOptions) {
  const auto torus = icd::make_torus(1.0, 0.3, 24, 12);
  const MeshOracle oracle(torus);
  const SurfaceSamples samples = sample_surface(torus.V, torus.F, SamplingOptions{0.05});
  const MedialSpheres medial;
  const PointGrid grid(samples.points, 0.5);
  const ReductionProblem problem{samples.points, samples.gap, medial, grid};
  FittedSphere a = start_spheres(samples, 6, 2).front(), b = a;
  polish_protrusion(problem, oracle, a, 9);
  polish_protrusion(problem, oracle, b, 9);
  EXPECT_EQ(a.center, b.center);
  EXPECT_EQ(a.radius, b.radius);
  ProtrusionPolishOptions bad;
  bad.search_directions = 0;
  EXPECT_THROW(polish_protrusion(problem, oracle, a, 9, bad), icd::ParameterError);
  bad = {};
  bad.min_step = 0;
  EXPECT_THROW(polish_protrusion(problem, oracle, a, 9, bad), icd::ParameterError);
}

}  // namespace
