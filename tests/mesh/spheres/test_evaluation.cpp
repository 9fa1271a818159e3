// Evaluation metrics against closed forms for spheres around a cube: probe
// errors (distance of outside probes to the cube), uncovered area (a sphere
// cap cuts a disk out of each face), uncovered corners, child protrusion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/evaluation.hpp>

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

TEST(Evaluation, RandomEstimatesDoNotDependOnTheSphereOrder) {
  // The shell and the rotated-probe errors draw random points per sphere;
  // the same spheres listed in another order must give the same estimates.
  const auto cube = icd::make_box_surface({-1, -1, -1}, {1, 1, 1});
  EvaluationOptions options;
  options.coverage_spacing = 50.0;
  options.shell_samples = 64;
  options.probe_rotations = 4;
  std::vector<icd::collision::Sphere> leaves;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0), ur(0.3, 0.9);
  for (int i = 0; i < 12; ++i) leaves.push_back({u(rng), u(rng), u(rng), ur(rng)});
  const auto forward = evaluate_sphere_tree(cube, root_over(leaves), options);
  std::reverse(leaves.begin(), leaves.end());
  const auto backward = evaluate_sphere_tree(cube, root_over(leaves), options);
  ASSERT_GT(forward[1].shell_thickness, 0.0);
  ASSERT_GT(forward[1].mean_error_42_rotated, 0.0);
  EXPECT_NEAR(backward[1].shell_thickness, forward[1].shell_thickness,
              1e-12 * forward[1].shell_thickness);
  EXPECT_NEAR(backward[1].mean_error_42_rotated, forward[1].mean_error_42_rotated,
              1e-12 * forward[1].mean_error_42_rotated);
  EXPECT_EQ(backward[1].worst_error_42_rotated, forward[1].worst_error_42_rotated);
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

/// Index of the row of `dirs` within `tol` of `d`, or -1.
int find_direction(const icd::MatX3d& dirs, const Eigen::Vector3d& d, double tol) {
  for (Eigen::Index k = 0; k < dirs.rows(); ++k)
    if ((dirs.row(k).transpose() - d).norm() < tol) return static_cast<int>(k);
  return -1;
}

TEST(Evaluation, ToolkitFrameGivesTheToolkitsFortyTwoPoints) {
  // The reference toolkit's icosahedron, from its published constants, and
  // its once-subdivided set: the vertices plus the normalized midpoints of
  // the 30 edges (the pairs at the shortest distance).
  const double X = .525731112119133606, Z = .850650808352039932;
  std::vector<Eigen::Vector3d> points = {{-X, 0, Z}, {X, 0, Z},  {-X, 0, -Z}, {X, 0, -Z},
                                         {0, Z, X},  {0, Z, -X}, {0, -Z, X},  {0, -Z, -X},
                                         {Z, X, 0},  {-Z, X, 0}, {Z, -X, 0},  {-Z, -X, 0}};
  const double edge = (points[0] - points[1]).norm();
  int edges = 0;
  for (int a = 0; a < 12; ++a) {
    for (int b = a + 1; b < 12; ++b) {
      if ((points[static_cast<size_t>(a)] - points[static_cast<size_t>(b)]).norm() > edge + 1e-9)
        continue;
      ++edges;
      points.push_back(
          (points[static_cast<size_t>(a)] + points[static_cast<size_t>(b)]).normalized());
    }
  }
  ASSERT_EQ(edges, 30);
  const icd::MatX3d toolkit = probe_directions(1) * toolkit_probe_frame().transpose();
  std::vector<int> matched;
  for (const auto& p : points) {
    const int k = find_direction(toolkit, p, 1e-6);
    EXPECT_GE(k, 0) << p.transpose();
    matched.push_back(k);
  }
  std::sort(matched.begin(), matched.end());
  EXPECT_EQ(std::unique(matched.begin(), matched.end()), matched.end());  // a bijection
  // Our own frame is another one: it lacks the toolkit's first vertex.
  EXPECT_LT(find_direction(probe_directions(1), points[0], 1e-3), 0);
}

/// The mesh and the tree mapped by x -> M x (faces flipped when det M < 0).
std::pair<icd::SurfaceMesh, icd::collision::SphereTree> mapped(
    const icd::SurfaceMesh& mesh, const icd::collision::SphereTree& tree,
    const Eigen::Matrix3d& M) {
  icd::SurfaceMesh m = mesh;
  m.V = mesh.V * M.transpose();
  if (M.determinant() < 0) m.F.col(1).swap(m.F.col(2));
  icd::collision::SphereTree t = tree;
  for (auto& s : t.spheres) {
    const Eigen::Vector3d c = M * s.center();
    s = {c.x(), c.y(), c.z(), s.r};
  }
  t.rest_spheres = t.spheres;
  return {m, t};
}

TEST(Evaluation, ProbeFrameTurnsTheProbesAsTurningTheModelWould) {
  // Probing in frame Q is probing the model turned by Q^T in our frame
  // (errors compared in model units: turning changes the bounding box).
  // A box turned off the axes: along an axis (a direction both frames
  // contain) the probes would see the same largest distance.
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  const auto box = mapped(icd::make_box_surface({-1, -0.6, -0.3}, {1, 0.6, 0.3}),
                          two_level_tree(1, {0, 0, 0}, 1), turn)
                       .first;
  const auto tree = two_level_tree(1.25, {0.35, 0.2, 0.1}, 0.55);
  std::mt19937 rng(0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Matrix3d random =
      Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
          .normalized()
          .toRotationMatrix();
  for (const Eigen::Matrix3d& Q : {random, toolkit_probe_frame()}) {
    EvaluationOptions in_frame;
    in_frame.coverage_spacing = 50.0;
    in_frame.shell_samples = 0;
    in_frame.probe_rotations = 0;
    in_frame.probe_frame = Q;
    const auto a = evaluate_sphere_tree(box, tree, in_frame);
    const auto [turned_box, turned_tree] = mapped(box, tree, Q.transpose());
    EvaluationOptions ours = in_frame;
    ours.probe_frame.setIdentity();
    const auto b = evaluate_sphere_tree(turned_box, turned_tree, ours);
    const auto side = [](const icd::SurfaceMesh& m) {
      return (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).maxCoeff();
    };
    const double to_model_a = side(box) / 2000.0, to_model_b = side(turned_box) / 2000.0;
    for (size_t l = 0; l < 2; ++l) {
      EXPECT_NEAR(a[l].worst_error_42 * to_model_a, b[l].worst_error_42 * to_model_b, 1e-9);
      EXPECT_NEAR(a[l].mean_error_162 * to_model_a, b[l].mean_error_162 * to_model_b, 1e-9);
    }
    EXPECT_GT(a[1].worst_error_42, 0.0);
  }
  // The frame changes what the probes see on this model.
  EvaluationOptions plain;
  plain.coverage_spacing = 50.0;
  plain.shell_samples = 0;
  EvaluationOptions toolkit = plain;
  toolkit.probe_frame = toolkit_probe_frame();
  EXPECT_NE(evaluate_sphere_tree(box, tree, plain)[1].worst_error_42,
            evaluate_sphere_tree(box, tree, toolkit)[1].worst_error_42);
  EvaluationOptions bad = plain;
  bad.probe_frame(0, 0) = 2.0;
  EXPECT_THROW(evaluate_sphere_tree(box, tree, bad), icd::ParameterError);
  bad = plain;
  bad.probe_rotations = -1;
  EXPECT_THROW(evaluate_sphere_tree(box, tree, bad), icd::ParameterError);
}

TEST(Evaluation, RotatedProbesAverageTheErrorOverOrientations) {
  // Spheres of radius r, centres at depth h under the top face of a wide,
  // deep slab: a probe c + r u sticks out by r u_z - h, so a sphere's error in
  // a frame turned by R is r max_k (R u_k)_z - h, and over uniformly random
  // R its mean is r E - h with E = mean over unit w of max_k u_k . w (the
  // 42-point set's mean half-width), integrated here on a Fibonacci lattice.
  const double r = 100, h = 50;
  const auto slab = icd::make_box_surface({-1000, -1000, -500}, {1000, 1000, 0});  // side 2000
  std::vector<icd::collision::Sphere> spheres;
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j) spheres.push_back({-600.0 + 200 * i, -600.0 + 200 * j, -h, r});
  auto tree = root_over(spheres);
  tree.spheres[0] = {0, 0, -250, 1500};
  tree.rest_spheres = tree.spheres;

  const icd::MatX3d u = probe_directions(1);
  const int lattice = 200000;
  double E = 0;
  for (int n = 0; n < lattice; ++n) {
    const double z = 1.0 - (2.0 * n + 1.0) / lattice, rho = std::sqrt(1.0 - z * z);
    const double phi = n * M_PI * (3.0 - std::sqrt(5.0));
    const Eigen::Vector3d w(rho * std::cos(phi), rho * std::sin(phi), z);
    E += (u * w).maxCoeff() / lattice;
  }
  ASSERT_GT(E, 0.95);
  ASSERT_LT(E, 1.0);

  EvaluationOptions options;
  options.coverage_spacing = 100.0;
  options.shell_samples = 0;
  options.probe_rotations = 64;
  const auto metrics = evaluate_sphere_tree(slab, tree, options);
  const LevelMetrics& m = metrics[1];
  // Our frame has a probe straight up (the midpoint of (0, 1, t) and (0, -1, t)).
  EXPECT_NEAR(m.mean_error_42, r - h, 1e-6);
  // 49 spheres x 64 orientations: the sampling spread of the mean is ~0.03.
  EXPECT_NEAR(m.mean_error_42_rotated, r * E - h, 0.25);
  EXPECT_LT(m.mean_error_42_rotated, m.mean_error_42 - 1.0);
  EXPECT_GE(m.worst_error_42_rotated, m.mean_error_42_rotated);
  EXPECT_LE(m.worst_error_42_rotated, r - h + 1e-9);
  // Fixed seeds: the same numbers again.
  EXPECT_EQ(evaluate_sphere_tree(slab, tree, options)[1].mean_error_42_rotated,
            m.mean_error_42_rotated);
  options.probe_rotations = 0;
  EXPECT_EQ(evaluate_sphere_tree(slab, tree, options)[1].mean_error_42_rotated, 0.0);
}

TEST(Evaluation, ThicknessQuantilesMatchTheCapOverACubeFace) {
  // A sphere of radius R about the centre of the cube [-1, 1]^3: from the
  // point (x, y, 1) of a face it reaches sqrt(R^2 - x^2 - y^2) - 1 along the
  // normal, where covered (x^2 + y^2 <= R^2 - 1), else the point counts 0.
  // The area-weighted quantiles over the surface are those over one face,
  // taken here on a fine grid of the square (normalized units: x 1000).
  const auto cube = icd::make_box_surface({-1, -1, -1}, {1, 1, 1});
  for (const double R : {2.0, 1.2}) {
    std::vector<double> reach;
    const int n = 1000;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const double x = -1 + (2.0 * i + 1) / n, y = -1 + (2.0 * j + 1) / n;
        const double left = R * R - x * x - y * y;
        reach.push_back(left >= 1.0 ? 1000.0 * (std::sqrt(left) - 1.0) : 0.0);
      }
    }
    std::sort(reach.begin(), reach.end());
    const double median = reach[reach.size() / 2], p90 = reach[reach.size() * 9 / 10];
    EvaluationOptions options;
    options.coverage_spacing = 4.0;
    options.shell_samples = 0;
    options.probe_rotations = 0;
    const auto m = evaluate_sphere_tree(cube, two_level_tree(R, {0, 0, 0}, R), options);
    SCOPED_TRACE("R = " + std::to_string(R));
    EXPECT_NEAR(m[1].thickness_median, median, 0.5);
    EXPECT_NEAR(m[1].thickness_p90, p90, 0.5);
    if (R < 1.5) {
      EXPECT_EQ(median, 0.0);  // most of each face is uncovered
      EXPECT_GT(p90, 100.0);
    }
  }
}

}  // namespace
