// MeshOracle and close_holes against analytic distances to a box and a sphere.
#include <gtest/gtest.h>

#include <random>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>

namespace {

using icd::mesh::MeshOracle;

/// Exact distance from p to the surface of the box [lo, hi].
double box_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                    const Eigen::Vector3d& hi) {
  const Eigen::Vector3d outside = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  if (outside.norm() > 0) return outside.norm();
  return std::min((p - lo).minCoeff(), (hi - p).minCoeff());
}

TEST(MeshOracle, BoxDistancesAndSidesMatchTheClosedForm) {
  const Eigen::Vector3d lo(0, 0, 0), hi(2, 1, 0.5);
  const MeshOracle oracle(icd::make_box_surface(lo, hi));
  std::mt19937 rng(0);
  std::uniform_real_distribution<double> u(-0.5, 2.5);
  for (int t = 0; t < 300; ++t) {
    const Eigen::Vector3d p(u(rng), u(rng) * 0.5, u(rng) * 0.3);
    const bool inside = (p.array() > lo.array()).all() && (p.array() < hi.array()).all();
    EXPECT_NEAR(oracle.distance(p), box_distance(p, lo, hi), 1e-9);
    EXPECT_EQ(oracle.inside(p), inside) << p.transpose();
    EXPECT_NEAR(oracle.signed_distance(p),
                inside ? box_distance(p, lo, hi) : -box_distance(p, lo, hi), 1e-9);
    EXPECT_NEAR(box_distance(oracle.closest_point(p), lo, hi), 0.0, 1e-9);
  }
}

TEST(MeshOracle, RejectsOpenMeshes) {
  icd::SurfaceMesh open = icd::make_icosphere(1);
  open.F.conservativeResize(open.F.rows() - 1, 3);
  EXPECT_THROW(MeshOracle{open}, icd::InputError);
}

TEST(CloseHoles, FillsBoundaryLoopsAndKeepsVertices) {
  const icd::SurfaceMesh sphere = icd::make_icosphere(2);
  icd::SurfaceMesh open = sphere;
  // Remove two non-adjacent faces: two holes.
  open.F.row(5) = open.F.row(open.F.rows() - 1);
  open.F.conservativeResize(open.F.rows() - 1, 3);
  open.F.row(100) = open.F.row(open.F.rows() - 1);
  open.F.conservativeResize(open.F.rows() - 1, 3);
  ASSERT_EQ(icd::mesh::count_boundary_edges(open.F), 6);
  const icd::SurfaceMesh closed = icd::mesh::close_holes(open);
  EXPECT_EQ(icd::mesh::count_boundary_edges(closed.F), 0);
  EXPECT_EQ(closed.V.rows(), open.V.rows());
  EXPECT_EQ(closed.F.rows(), sphere.F.rows());
  EXPECT_NEAR(icd::mesh::surface_area(closed.V, closed.F),
              icd::mesh::surface_area(sphere.V, sphere.F), 1e-9);
  const MeshOracle oracle(closed);
  EXPECT_TRUE(oracle.inside(Eigen::Vector3d(0.1, 0.2, 0.1)));
  EXPECT_FALSE(oracle.inside(Eigen::Vector3d(1.1, 0, 0)));
  // A closed mesh comes back unchanged.
  EXPECT_EQ(icd::mesh::close_holes(sphere).F, sphere.F);
}

}  // namespace
