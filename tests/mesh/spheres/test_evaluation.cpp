// Evaluation metrics against closed forms for spheres around a cube: probe
// errors (distance of outside probes to the cube), uncovered area (a sphere
// cap cuts a disk out of each face), uncovered corners, child protrusion.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "collision/sphere_tree.hpp"
#include "mesh/io/error.hpp"
#include "mesh/io/primitives.hpp"
#include "mesh/spheres/evaluation.hpp"

namespace {

using namespace icd::mesh;

icd::collision::SphereTree two_level_tree(double root_r, const Eigen::Vector3d& child_c,
                                          double child_r) {
  icd::collision::SphereTree t;
  t.spheres = {{0, 0, 0, root_r}, {child_c.x(), child_c.y(), child_c.z(), child_r}};
  t.rest_spheres = t.spheres;
  t.first_child = {1, -1};
  t.child_count = {1, 0};
  t.level = {0, 1};
  t.level_offset = {0, 1, 2};
  return t;
}

/// Exact distance from an outside point to the cube [-h, h]^3.
double cube_distance(const Eigen::Vector3d& p, double h) {
  return (p.cwiseAbs().array() - h).max(0.0).matrix().norm();
}

TEST(Evaluation, ProbeErrorsMatchTheCubeDistance) {
  const auto cube = icd::make_box_surface({-1, -1, -1}, {1, 1, 1});  // normalized: half side 1000
  const auto tree = two_level_tree(1.2, {0.3, 0.1, 0}, 1.05);
  EvaluationOptions options;
  options.coverage_spacing = 20.0;
  const auto metrics = evaluate_sphere_tree(cube, tree, options);
  ASSERT_EQ(metrics.size(), 2u);
  for (int subdivisions : {1, 2}) {
    const icd::MatX3d dirs = probe_directions(subdivisions);
    ASSERT_EQ(dirs.rows(), subdivisions == 1 ? 42 : 162);
    for (int node = 0; node < 2; ++node) {
      const auto& s = tree.spheres[node];
      double expected = 0;
      for (Eigen::Index d = 0; d < dirs.rows(); ++d) {
        const Eigen::Vector3d p = 1000.0 * (s.center() + s.r * dirs.row(d).transpose());
        expected = std::max(expected, cube_distance(p, 1000.0));
      }
      const auto& m = metrics[static_cast<size_t>(node)];
      EXPECT_NEAR(subdivisions == 1 ? m.worst_error_42 : m.worst_error_162, expected, 1e-6);
      EXPECT_NEAR(subdivisions == 1 ? m.mean_error_42 : m.mean_error_162, expected, 1e-6);
    }
  }
  // The child sticks out of the root by |c| + r_child - r_root.
  EXPECT_NEAR(metrics[1].max_child_protrusion, 1000.0 * (std::sqrt(0.1) + 1.05 - 1.2), 1e-6);
  EXPECT_EQ(metrics[0].max_child_protrusion, 0.0);
}

TEST(Evaluation, UncoveredAreaMatchesTheFaceDiskClosedForm) {
  const auto cube = icd::make_box_surface({-1, -1, -1}, {1, 1, 1});
  const double R = 1.2;
  const auto tree =
      two_level_tree(R, {0, 0, 0}, std::sqrt(3.0) + 1e-9);  // the child covers everything
  EvaluationOptions options;
  options.coverage_spacing = 5.0;
  const auto metrics = evaluate_sphere_tree(cube, tree, options);
  // Each face keeps a covered disk of radius sqrt(R^2 - 1) (< 1) around its centre.
  const double rho2 = R * R - 1.0;
  const double expected = 1.0 - M_PI * rho2 / 4.0;
  EXPECT_NEAR(metrics[0].uncovered_area_fraction, expected, 0.005);
  EXPECT_EQ(metrics[0].num_uncovered_vertices, 8);
  EXPECT_NEAR(metrics[0].max_uncovered_gap, 1000.0 * (std::sqrt(3.0) - R), 1e-6);
  EXPECT_EQ(metrics[1].num_uncovered_samples, 0);
  EXPECT_EQ(metrics[1].uncovered_area_fraction, 0.0);
  EXPECT_EQ(metrics[1].num_uncovered_vertices, 0);
}

/// Root (radius 2, covers the cube) over one level of `children` spheres.
icd::collision::SphereTree root_over(const std::vector<icd::collision::Sphere>& children) {
  icd::collision::SphereTree t;
  t.spheres = {{0, 0, 0, 2.0}};
  t.spheres.insert(t.spheres.end(), children.begin(), children.end());
  t.rest_spheres = t.spheres;
  const int n = static_cast<int>(children.size());
  t.first_child.assign(static_cast<size_t>(n) + 1, -1);
  t.first_child[0] = 1;
  t.child_count.assign(static_cast<size_t>(n) + 1, 0);
  t.child_count[0] = n;
  t.level.assign(static_cast<size_t>(n) + 1, 1);
  t.level[0] = 0;
  t.level_offset = {0, 1, n + 1};
  return t;
}

/// 42-probe error of a sphere of the cube [-1, 1]^3 (normalized units).
double cube_error_42(const icd::collision::Sphere& s) {
  const icd::MatX3d dirs = probe_directions(1);
  double e = 0;
  for (Eigen::Index d = 0; d < dirs.rows(); ++d)
    e = std::max(e, cube_distance(1000.0 * (s.center() + s.r * dirs.row(d).transpose()), 1000.0));
  return e;
}

TEST(Evaluation, CountsSpheresThatCoverNothingAlone) {
  const auto cube = icd::make_box_surface({-1, -1, -1}, {1, 1, 1});
  EvaluationOptions options;
  options.coverage_spacing = 20.0;
  // Two halves, each alone over the corners of its side (|(1, 1, 1) - (-0.5, 0, 0)| = 2.06 >
  // 1.51); one sphere inside touching only the face centres, which the halves cover too; one
  // tucked inside the object, touching nothing.
  const icd::collision::Sphere left{-0.5, 0, 0, 1.51}, right{0.5, 0, 0, 1.51}, middle{0, 0, 0, 1.0},
      inner{0.2, 0.1, 0, 0.4};
  const auto metrics = evaluate_sphere_tree(cube, root_over({left, middle, right, inner}), options);
  ASSERT_EQ(metrics.size(), 2u);
  EXPECT_EQ(metrics[1].num_uncovered_samples, 0);
  EXPECT_EQ(metrics[1].num_redundant_spheres, 2);
  EXPECT_NEAR(metrics[1].mean_error_42_covering, 0.5 * (cube_error_42(left) + cube_error_42(right)),
              1e-6);
  EXPECT_NEAR(metrics[1].mean_error_42,
              0.25 * (cube_error_42(left) + cube_error_42(right) + cube_error_42(middle) +
                      cube_error_42(inner)),
              1e-6);
  EXPECT_EQ(metrics[0].num_redundant_spheres, 0);
  EXPECT_NEAR(metrics[0].mean_error_42_covering, metrics[0].mean_error_42, 1e-9);

  // Redundancy is per sphere: two copies of a covering sphere can each be removed alone.
  const icd::collision::Sphere whole{0, 0, 0, std::sqrt(3.0) + 1e-6};
  const auto twice = evaluate_sphere_tree(cube, root_over({whole, whole}), options);
  EXPECT_EQ(twice[1].num_redundant_spheres, 2);
  // Without the middle and inner spheres nothing is redundant.
  const auto halves = evaluate_sphere_tree(cube, root_over({left, right}), options);
  EXPECT_EQ(halves[1].num_redundant_spheres, 0);
  EXPECT_NEAR(halves[1].mean_error_42_covering, halves[1].mean_error_42, 1e-9);
}

TEST(Evaluation, ShellThicknessIsTheUnionVolumeOutsideOverTheArea) {
  const auto cube = icd::make_box_surface({-1, -1, -1}, {1, 1, 1});
  EvaluationOptions options;
  options.coverage_spacing = 50.0;
  options.shell_samples = 20000;
  // A sphere of radius R < sqrt(2) about the centre sticks out of each face by
  // a cap of height h = R - 1 and volume pi h^2 (3R - h) / 3; the area is 24.
  const double R = 1.2, h = R - 1;
  const double expected = 1000.0 * 6 * M_PI * h * h * (3 * R - h) / 3 / 24;  // normalized units
  const icd::collision::Sphere ball{0, 0, 0, R}, inner{0.1, 0, 0, 0.5};
  const auto one = evaluate_sphere_tree(cube, root_over({ball}), options);
  EXPECT_NEAR(one[1].shell_thickness, expected, 0.02 * expected);
  // A copy of the sphere and a sphere inside the object add no volume.
  const auto more = evaluate_sphere_tree(cube, root_over({ball, inner, ball}), options);
  EXPECT_NEAR(more[1].shell_thickness, expected, 0.02 * expected);
  const auto inside = evaluate_sphere_tree(cube, root_over({inner}), options);
  EXPECT_EQ(inside[1].shell_thickness, 0.0);
  options.shell_samples = -1;
  EXPECT_THROW(evaluate_sphere_tree(cube, root_over({ball}), options), icd::ParameterError);
}

TEST(Evaluation, RejectsBadOptionsAndTrees) {
  const auto cube = icd::make_box_surface({-1, -1, -1}, {1, 1, 1});
  EvaluationOptions bad;
  bad.coverage_spacing = 0;
  EXPECT_THROW(evaluate_sphere_tree(cube, two_level_tree(2, {0, 0, 0}, 2), bad),
               icd::ParameterError);
  auto tree = two_level_tree(2, {0, 0, 0}, 2);
  tree.spheres[1].r = std::nan("");
  EXPECT_THROW(evaluate_sphere_tree(cube, tree), icd::ParameterError);
  EXPECT_THROW(evaluate_sphere_tree(cube, icd::collision::SphereTree{}), icd::ParameterError);
}

}  // namespace
