#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include "mesh/pipeline/pipeline_test_utils.hpp"
#include <icd/mesh/pipeline/simplify.hpp>
#include <icd/mesh/pipeline/tetrahedralize.hpp>

namespace icd::mesh {
namespace {

using test::closed_and_oriented;
using test::enclosed_volume;

TEST(Simplify, SphereToTargetStaysOnSphere) {
  const SurfaceMesh s = make_icosphere(4);  // 5120 faces
  SimplifyOptions o;
  o.target_faces = 500;
  const SimplifyResult r = simplify_surface(s, o);
  EXPECT_LE(r.mesh.F.rows(), 500);
  EXPECT_GE(r.mesh.F.rows(), 450);
  EXPECT_EQ(r.report.output_faces, r.mesh.F.rows());
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  EXPECT_TRUE(
      test::all_vertices_used(static_cast<int>(r.mesh.V.rows()), r.mesh.F.data(), r.mesh.F.size()));
  // Analytic oracle: vertices stay near the unit sphere, the volume near 4/3 pi.
  const double max_dev = (r.mesh.V.rowwise().norm().array() - 1.0).abs().maxCoeff();
  EXPECT_LT(max_dev, 0.02);
  EXPECT_NEAR(enclosed_volume(r.mesh.V, r.mesh.F) / (4.0 / 3.0 * std::numbers::pi), 1.0, 0.03);
}

TEST(Simplify, RatioTargetAndBadOptions) {
  const SurfaceMesh s = make_torus(1.0, 0.4, 40, 20);  // 1600 faces
  SimplifyOptions o;
  o.target_faces = 0;
  o.target_ratio = 0.25;
  const SimplifyResult r = simplify_surface(s, o);
  EXPECT_LE(r.mesh.F.rows(), 400);
  EXPECT_GE(r.mesh.F.rows(), 360);
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  o.target_ratio = 1.5;
  EXPECT_THROW(simplify_surface(s, o), ParameterError);
  o.target_faces = -3;
  EXPECT_THROW(simplify_surface(s, o), ParameterError);
}

// Structural invariants of a tet mesh made from `surface`, against
// independent computations (boundary via a directed-edge check, volumes).
void check_tet_mesh(const TetrahedralizeResult& r, double expected_volume, double volume_tol) {
  const TetMesh& m = r.mesh;
  ASSERT_GT(m.T.rows(), 0);
  EXPECT_TRUE(test::all_vertices_used(static_cast<int>(m.V.rows()), m.T.data(), m.T.size()));
  const Eigen::VectorXd vol = signed_tet_volumes(m.V, m.T);
  EXPECT_GT(vol.minCoeff(), 0.0);
  EXPECT_TRUE(closed_and_oriented(m.F));
  // Outward: the boundary encloses exactly the sum of the tet volumes.
  EXPECT_NEAR(enclosed_volume(m.V, m.F), vol.sum(), 1e-10 * vol.sum());
  EXPECT_NEAR(vol.sum() / expected_volume, 1.0, volume_tol);
  EXPECT_NEAR(r.quality.total_volume, vol.sum(), 1e-10 * vol.sum());
  EXPECT_EQ(r.quality.num_tets, m.T.rows());
}

TEST(Tetrahedralize, SphereQualityAndCount) {
  const SurfaceMesh s = make_icosphere(3);
  TetrahedralizeOptions o;
  o.target_tets = 600;
  const TetrahedralizeResult r = tetrahedralize_surface(s, o);
  check_tet_mesh(r, 4.0 / 3.0 * std::numbers::pi, 0.08);
  std::cout << "  " << r.quality.to_string() << "  passes " << r.passes << " cell size "
            << r.cell_size << "\n";
  EXPECT_LE(std::abs(r.quality.num_tets / 600.0 - 1.0), o.count_tolerance + 0.25);
  // Sliver removal: no dihedral angle below 5 deg, none above 170 deg.
  EXPECT_GT(r.quality.min_dihedral_deg, 5.0);
  EXPECT_LT(r.quality.max_dihedral_deg, 170.0);
  EXPECT_LT(r.quality.max_radius_edge, 2.0 * o.radius_edge_bound);
  EXPECT_GT(r.quality.min_volume, 0.0);
}

TEST(Tetrahedralize, TorusAndBoxVolumes) {
  TetrahedralizeOptions o;
  o.target_tets = 800;
  const SurfaceMesh torus = make_torus(1.0, 0.35, 48, 24);
  const TetrahedralizeResult rt = tetrahedralize_surface(torus, o);
  check_tet_mesh(rt, enclosed_volume(torus.V, torus.F), 0.08);
  o.target_tets = 300;
  const SurfaceMesh box = make_box_surface({0, 0, 0}, {2, 1, 1});
  const TetrahedralizeResult rb = tetrahedralize_surface(box, o);
  check_tet_mesh(rb, 2.0, 0.1);  // sharp edges are not protected: rounded slightly
}

TEST(Tetrahedralize, DeterministicForSameInput) {
  const SurfaceMesh s = make_icosphere(2);
  TetrahedralizeOptions o;
  o.target_tets = 300;
  const TetrahedralizeResult a = tetrahedralize_surface(s, o);
  const TetrahedralizeResult b = tetrahedralize_surface(s, o);
  ASSERT_EQ(a.mesh.V.rows(), b.mesh.V.rows());
  ASSERT_EQ(a.mesh.T.rows(), b.mesh.T.rows());
  EXPECT_TRUE(a.mesh.V == b.mesh.V);  // bitwise
  EXPECT_TRUE(a.mesh.T == b.mesh.T);
}

TEST(Tetrahedralize, SmallerInteriorSizeAddsInteriorNodes) {
  // The same surface sizing with the cells inside bounded at half the size:
  // more nodes inside (counted from the tets' boundary), still a valid mesh.
  const SurfaceMesh s = make_icosphere(3);
  TetrahedralizeOptions o;
  o.cell_size = 0.5;
  const TetrahedralizeResult a = tetrahedralize_surface(s, o);
  o.interior_size_factor = 0.5;
  const TetrahedralizeResult b = tetrahedralize_surface(s, o);
  check_tet_mesh(b, 4.0 / 3.0 * std::numbers::pi, 0.08);
  const auto interior = [](const TetMesh& m) {
    return m.V.rows() - static_cast<Eigen::Index>(boundary_nodes(m.F).size());
  };
  std::cout << "  interior nodes " << interior(a.mesh) << " -> " << interior(b.mesh) << " of "
            << a.mesh.V.rows() << " -> " << b.mesh.V.rows() << "\n";
  EXPECT_GT(interior(b.mesh), interior(a.mesh) + 5);
  o.interior_size_factor = 1.5;
  EXPECT_THROW(tetrahedralize_surface(s, o), ParameterError);
}

TEST(Tetrahedralize, RefusesOpenOrInvertedSurface) {
  SurfaceMesh s = make_icosphere(1);
  SurfaceMesh open = s;
  open.F.conservativeResize(s.F.rows() - 1, 3);
  EXPECT_THROW(tetrahedralize_surface(open), InputError);
  SurfaceMesh inv = s;
  inv.F.col(1).swap(inv.F.col(2));
  EXPECT_THROW(tetrahedralize_surface(inv), InputError);
  TetrahedralizeOptions o;
  o.radius_edge_bound = 1.0;
  EXPECT_THROW(tetrahedralize_surface(s, o), ParameterError);
}

}  // namespace
}  // namespace icd::mesh
