#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/pipeline/tet_quality.hpp>

namespace icd::mesh {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

TEST(TetQuality, RegularTetAnalytic) {
  // Regular tet of edge 2 sqrt(2) from alternate cube corners.
  const Eigen::Vector3d a(1, 1, 1), b(1, -1, -1), c(-1, 1, -1), d(-1, -1, 1);
  const TetShape s = tet_shape(a, b, c, d);
  for (double ang : s.dihedral_deg) EXPECT_NEAR(ang, std::acos(1.0 / 3.0) * kDeg, 1e-10);
  EXPECT_NEAR(s.radius_edge, std::sqrt(6.0) / 4.0, 1e-12);
  EXPECT_NEAR(std::abs(s.volume), std::pow(2 * std::sqrt(2.0), 3) / (6 * std::sqrt(2.0)), 1e-12);
}

TEST(TetQuality, CornerTetAnalytic) {
  const TetMesh t = make_unit_tet();
  const TetShape s = tet_shape(t.V.row(0), t.V.row(1), t.V.row(2), t.V.row(3));
  // Edges at the right-angle corner (01, 02, 03): 90 deg; the others acos(1/sqrt 3).
  for (int e = 0; e < 3; ++e) EXPECT_NEAR(s.dihedral_deg[e], 90.0, 1e-10);
  for (int e = 3; e < 6; ++e)
    EXPECT_NEAR(s.dihedral_deg[e], std::acos(1 / std::sqrt(3.0)) * kDeg, 1e-10);
  EXPECT_NEAR(s.radius_edge, std::sqrt(3.0) / 2.0, 1e-12);  // R = sqrt(3)/2, shortest edge 1
  EXPECT_NEAR(s.volume, 1.0 / 6.0, 1e-15);
  const TetQuality q = tet_quality(t);
  EXPECT_EQ(q.num_tets, 1);
  EXPECT_EQ(q.num_surface_nodes, 4);
  EXPECT_NEAR(q.min_dihedral_deg, std::acos(1 / std::sqrt(3.0)) * kDeg, 1e-10);
  EXPECT_NEAR(q.max_dihedral_deg, 90.0, 1e-10);
}

TEST(TetQuality, FlatTetIsInfinitelyBad) {
  const TetShape s = tet_shape({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0});
  EXPECT_EQ(s.volume, 0.0);
  EXPECT_TRUE(std::isinf(s.radius_edge));
}

TEST(TetQuality, BoxMeshVolume) {
  BoxMeshOptions o;
  o.size = {2.0, 1.0, 0.5};
  o.nx = 4;
  o.ny = 2;
  o.nz = 1;
  const TetQuality q = tet_quality(make_box_tet_mesh(o));
  EXPECT_NEAR(q.total_volume, 1.0, 1e-12);
  EXPECT_GT(q.min_volume, 0.0);
}

}  // namespace
}  // namespace icd::mesh
