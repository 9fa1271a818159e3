// The stable-step post-pass (tet_cleanup.hpp): it removes the light node of a
// thin cap on a near-regular block and leaves the block itself alone; the
// stable step is checked with the FEM module's estimate (fem_step.hpp), the
// mesh with the same closed-manifold test as the mesher's.
#include <icd/mesh/pipeline/tet_cleanup.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/core/triangle_geometry.hpp>
#include <icd/mesh/pipeline/fem_step.hpp>
#include <icd/mesh/pipeline/tet_quality.hpp>

#include "sliver_block.hpp"

namespace icd::mesh {
namespace {

// Each directed boundary edge once and its reverse once: a closed manifold.
bool closed_manifold(const TetMesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++directed[{m.F(f, k), m.F(f, (k + 1) % 3)}];
  for (const auto& [e, n] : directed) {
    const auto rev = directed.find({e.second, e.first});
    if (n != 1 || rev == directed.end() || rev->second != 1) return false;
  }
  return true;
}

/// The centre sliver (test::bcc_block_with_centre_sliver): the mesh to clean,
/// a copy as made, its volume, and cleanup options with collapses off.
struct CentreSliver {
  TetMesh m, before;
  double volume0 = 0;
  StepCleanupOptions o;
};

CentreSliver centre_sliver_without_collapses() {
  CentreSliver c;
  if (!test::bcc_block_with_centre_sliver(c.m))
    throw std::runtime_error("bcc_block_with_centre_sliver: no sliver made");
  c.before = c.m;
  c.volume0 = signed_tet_volumes(c.m.V, c.m.T).sum();
  c.o.max_collapses = 0;
  return c;
}

TEST(TetCleanup, NearRegularBlockIsLeftAlone) {
  TetMesh m = bcc_block(4, 0.1);
  const TetMesh before = m;
  const StepCleanupReport r = raise_stable_step(m);
  EXPECT_EQ(r.collapses, 0);
  EXPECT_EQ(r.stuck, 0);
  EXPECT_GT(r.ratio_before, 0.6);
  EXPECT_EQ(m.T, before.T);
  EXPECT_EQ(m.V, before.V);
}

TEST(TetCleanup, ThinCapIsRemovedAndTheStepRecovers) {
  // A flat tet on a boundary face: its apex holds a 60th of a mean node's
  // mass and sets the step of the whole block.
  const double h = 0.1;
  TetMesh m = bcc_block(4, h);
  const Eigen::Vector3d a = m.V.row(m.F(0, 0)), b = m.V.row(m.F(0, 1)), c = m.V.row(m.F(0, 2));
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  const Eigen::Vector3d apex = (a + b + c) / 3 + 0.03 * h * n;
  m.V.conservativeResize(m.V.rows() + 1, 3);
  m.V.row(m.V.rows() - 1) = apex.transpose();
  m.T.conservativeResize(m.T.rows() + 1, 4);
  m.T.row(m.T.rows() - 1) << m.F(0, 0), m.F(0, 1), m.F(0, 2), static_cast<int>(m.V.rows() - 1);
  m.F = boundary_faces(m.T);
  ASSERT_TRUE(closed_manifold(m));
  const StableStepReport fem_before = stable_step_report(m);
  ASSERT_LT(fem_before.ratio, 0.4);  // the cap costs more than half the step
  const double volume_before = signed_tet_volumes(m.V, m.T).sum();

  const StepCleanupReport r = raise_stable_step(m);
  EXPECT_GE(r.collapses, 1);
  // The node estimate is a lower bound of the top frequency: its ratio an
  // upper bound of the FEM ratio, and close to it here.
  EXPECT_NEAR(r.ratio_before, fem_before.ratio, 0.05 * fem_before.ratio);
  const StableStepReport fem_after = stable_step_report(m);
  EXPECT_GT(fem_after.ratio, 0.9);
  EXPECT_LE(fem_after.ratio, r.ratio_after * 1.0001);
  EXPECT_TRUE(closed_manifold(m));
  EXPECT_EQ(m.V.rows(), bcc_block(4, h).V.rows());  // the apex is gone, nothing else
  EXPECT_GT(signed_tet_volumes(m.V, m.T).minCoeff(), 0.0);
  EXPECT_NEAR(signed_tet_volumes(m.V, m.T).sum(), volume_before, 0.01 * volume_before);
  EXPECT_NEAR(r.volume_change, signed_tet_volumes(m.V, m.T).sum() / volume_before - 1, 1e-12);
}

TEST(TetCleanup, SliverBelowTheDihedralTargetIsRemoved) {
  // An interior lattice node moved 92 % of the way to the plane of the
  // opposite face of one of its tets: a flat sliver (below 10 deg) that does
  // not limit the step much (ratio ~0.7, above the step target). The
  // dihedral phase removes it, keeping the step above the step target.
  TetMesh m;
  ASSERT_TRUE(test::bcc_block_with_centre_sliver(m));
  const TetQuality q0 = tet_quality(m);
  const double volume0 = signed_tet_volumes(m.V, m.T).sum();
  StableStepOptions so;
  so.mass_scaling_target = 0;
  const StableStepReport fem0 = stable_step_report(m, so);
  ASSERT_GT(fem0.ratio, 0.6);  // the step phase has nothing to do

  TetMesh off = m;
  StepCleanupOptions o;
  o.dihedral_target_deg = 0;
  const StepCleanupReport r_off = raise_stable_step(off, o);
  EXPECT_EQ(r_off.collapses + r_off.dihedral_collapses, 0);
  EXPECT_EQ(off.T, m.T);

  const StepCleanupReport r = raise_stable_step(m);
  EXPECT_EQ(r.collapses, 0);
  EXPECT_GE(r.dihedral_collapses, 1);
  const TetQuality q1 = tet_quality(m);
  EXPECT_NEAR(r.min_dihedral_before, q0.min_dihedral_deg, 1e-9);
  EXPECT_NEAR(r.min_dihedral_after, q1.min_dihedral_deg, 1e-9);
  EXPECT_GE(q1.min_dihedral_deg, 12.0);
  EXPECT_TRUE(closed_manifold(m));
  EXPECT_GT(signed_tet_volumes(m.V, m.T).minCoeff(), 0.0);
  EXPECT_NEAR(signed_tet_volumes(m.V, m.T).sum(), volume0, 1e-9 * volume0);  // interior only
  // The node estimate of the ratio stays at or above the target (0.6); the
  // FEM ratio is below the node estimate (a lower bound of omega_max) but close.
  EXPECT_GE(r.ratio_after, 0.6);
  const StableStepReport fem1 = stable_step_report(m, so);
  EXPECT_GT(fem1.ratio, 0.9 * 0.6);
  EXPECT_LE(fem1.ratio, r.ratio_after * 1.0001);
}

TEST(TetCleanup, SliverIsRelocatedAwayWhenNoCollapseIsAllowed) {
  // The same centre sliver with collapses off (max_collapses 0): the
  // relocation phase moves a node of the sliver instead; the connectivity,
  // every other node and the volume (the moved node is interior) stay.
  auto [m, before, volume0, o] = centre_sliver_without_collapses();
  o.flips = false;  // this test is about the relocation phase (flips: the next test)
  const StepCleanupReport r = raise_stable_step(m, o);
  EXPECT_EQ(r.collapses + r.dihedral_collapses + r.flips + r.drops, 0);
  EXPECT_GE(r.relocations, 1);
  EXPECT_EQ(m.T, before.T);
  EXPECT_EQ(m.F, before.F);
  int moved = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) moved += m.V.row(i) != before.V.row(i);
  EXPECT_EQ(moved, 1);  // one node of the sliver, once
  const TetQuality q = tet_quality(m);
  EXPECT_LT(tet_quality(before).min_dihedral_deg, 10.0);
  EXPECT_GE(q.min_dihedral_deg, 12.0);
  EXPECT_NEAR(r.min_dihedral_after, q.min_dihedral_deg, 1e-9);
  EXPECT_GT(q.min_volume, 0.0);
  EXPECT_NEAR(signed_tet_volumes(m.V, m.T).sum(), volume0, 1e-9 * volume0);
  // Off: nothing moves.
  TetMesh off = before;
  o.max_relocation_sweeps = 0;
  EXPECT_EQ(raise_stable_step(off, o).relocations, 0);
  EXPECT_EQ(off.V, before.V);
}

// Boundary faces as sorted triples (the boundary as a set, whatever its order).
std::set<std::array<int, 3>> face_set(const MatX3i& F) {
  std::set<std::array<int, 3>> s;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    std::array<int, 3> k{F(f, 0), F(f, 1), F(f, 2)};
    std::sort(k.begin(), k.end());
    s.insert(k);
  }
  return s;
}

TEST(TetCleanup, SliverIsFlippedAwayWhenNoCollapseOrRelocationIsAllowed) {
  // The centre sliver with collapses and relocations off: the flips replace
  // it and its neighbours by tets of the same nodes filling the same region
  // (every node where it was, the same boundary and volume, positive tets).
  auto [m, before, volume0, o] = centre_sliver_without_collapses();
  o.max_relocation_sweeps = 0;
  TetMesh off = m;
  o.flips = false;
  const StepCleanupReport r_off = raise_stable_step(off, o);
  EXPECT_EQ(r_off.flips + r_off.drops, 0);
  EXPECT_EQ(off.T, before.T);
  o.flips = true;
  const StepCleanupReport r = raise_stable_step(m, o);
  EXPECT_EQ(r.collapses + r.dihedral_collapses + r.relocations + r.drops, 0);
  EXPECT_GE(r.flips, 1);
  EXPECT_EQ(m.V, before.V);
  EXPECT_EQ(face_set(m.F), face_set(before.F));
  EXPECT_NE(m.T, before.T);
  const TetQuality q0 = tet_quality(before), q = tet_quality(m);
  EXPECT_LT(q0.min_dihedral_deg, 10.0);
  EXPECT_GE(q.min_dihedral_deg, 12.0);
  EXPECT_NEAR(r.min_dihedral_after, q.min_dihedral_deg, 1e-9);
  EXPECT_GT(q.min_volume, 0.0);
  EXPECT_NEAR(signed_tet_volumes(m.V, m.T).sum(), volume0, 1e-12 * volume0);
  EXPECT_TRUE(closed_manifold(m));
  // No face in more than two tets (the flips made a tet mesh, not overlaps).
  std::map<std::array<int, 3>, int> faces;
  for (Eigen::Index e = 0; e < m.T.rows(); ++e)
    for (int k = 0; k < 4; ++k) {
      std::array<int, 3> f{m.T(e, (k + 1) % 4), m.T(e, (k + 2) % 4), m.T(e, (k + 3) % 4)};
      std::sort(f.begin(), f.end());
      EXPECT_LE(++faces[f], 2);
    }
}

TEST(TetCleanup, BoundarySliverIsDropped) {
  // A structured (Kuhn) cube of 3^3 cells with a flat tet glued on a
  // boundary face (a, b, c): its apex d 5 % of an edge above the plane, over
  // a point beyond the edge ab, so that no flip can replace it (the segment
  // from d to the tet under the face misses the face; its other edges are on
  // the boundary or in no other tet) and collapses and relocations are not
  // allowed here. The drop removes it: the cube's own tets and boundary come
  // back, d (in no other tet) is gone.
  BoxMeshOptions bo;
  bo.size = {1, 1, 1};
  bo.nx = bo.ny = bo.nz = 3;
  const TetMesh block = make_box_tet_mesh(bo);
  const int a = block.F(0, 0), b = block.F(0, 1), c = block.F(0, 2);
  const Eigen::Vector3d pa = block.V.row(a), pb = block.V.row(b), pc = block.V.row(c);
  const Eigen::Vector3d n = (pb - pa).cross(pc - pa).normalized();  // outward
  const Eigen::Vector3d g = (pa + pb + pc) / 3, mid = (pa + pb) / 2;
  TetMesh m = block;
  const int d = static_cast<int>(m.V.rows());
  m.V.conservativeResize(d + 1, 3);
  m.V.row(d) = (mid + 0.6 * (mid - g) + 0.05 * (pa - pb).norm() * n).transpose();
  Eigen::RowVector4i t(a, b, c, d);
  if (signed_tet_volumes(m.V, MatX4i(t)).minCoeff() < 0) std::swap(t[2], t[3]);
  m.T.conservativeResize(m.T.rows() + 1, 4);
  m.T.row(m.T.rows() - 1) = t;
  m.F = boundary_faces(m.T);
  ASSERT_TRUE(closed_manifold(m));
  ASSERT_GT(signed_tet_volumes(m.V, m.T).minCoeff(), 0.0);
  ASSERT_LT(tet_quality(m).min_dihedral_deg, 10.0);
  ASSERT_GE(tet_quality(block).min_dihedral_deg, 12.0);
  const double volume_block = signed_tet_volumes(block.V, block.T).sum();
  const double volume_cap = signed_tet_volumes(m.V, MatX4i(t)).sum();
  StepCleanupOptions o;
  o.max_collapses = 0;
  o.max_relocation_sweeps = 0;
  TetMesh off = m;
  const StepCleanupReport r = raise_stable_step(m, o);
  EXPECT_EQ(r.drops, 1);
  EXPECT_EQ(r.flips, 0);
  EXPECT_EQ(m.V, block.V);
  EXPECT_EQ(m.T, block.T);
  EXPECT_EQ(face_set(m.F), face_set(block.F));
  EXPECT_GE(r.min_dihedral_after, 12.0);
  EXPECT_NEAR(r.volume_change, volume_block / (volume_block + volume_cap) - 1, 1e-12);
  // Off: the sliver stays.
  o.flips = false;
  EXPECT_EQ(raise_stable_step(off, o).drops, 0);
  EXPECT_EQ(off.T.rows(), block.T.rows() + 1);
}

TEST(TetCleanup, SliverOfASlabOneTetThickIsLiftedOffTheSurface) {
  // A slab one cell thick (Kuhn tets of 3 x 3 x 1 cells: every node on the
  // surface, as on the corpus' knots) with the top node at (1/3, 1/3) pushed
  // down until one of its tets falls below 11 deg: a sliver whose four nodes
  // lie on the surface. With collapses and flips off and surface nodes held
  // on their place along the boundary (max_shift 0: here sliding the node
  // along the dent would also do, on the knots it did not), only the last
  // phase can lift it (checked: with max_off_surface 0 it stays): it moves
  // a surface node off the boundary, by at most max_off_surface of the
  // diagonal, until every tet is at 12 deg or more; the connectivity stays.
  BoxMeshOptions bo;
  bo.size = {1, 1, 0.3};
  bo.nx = bo.ny = 3;
  bo.nz = 1;
  TetMesh m = make_box_tet_mesh(bo);
  const int c = 1 + 4 * (1 + 4 * 1);  // vertex (1, 1, 1): index i + (nx+1)(j + (ny+1)k)
  ASSERT_NEAR(m.V(c, 2), 0.3, 1e-12);
  double push = 0;
  while (tet_quality(m).min_dihedral_deg >= 11.0 && push < 0.3) {
    push += 0.002;
    m.V(c, 2) = 0.3 - push;
  }
  m.F = boundary_faces(m.T);
  ASSERT_TRUE(closed_manifold(m));
  ASSERT_GT(signed_tet_volumes(m.V, m.T).minCoeff(), 0.0);
  const TetQuality q0 = tet_quality(m);
  ASSERT_LT(q0.min_dihedral_deg, 11.0);
  const TetMesh before = m;
  const double diagonal = (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).norm();

  StepCleanupOptions o;
  o.max_collapses = 0;
  o.flips = false;
  o.max_shift = 0;
  o.max_volume_change = 0.05;
  o.max_off_surface = push / diagonal;  // enough to lift the node back
  TetMesh off = m;
  const StepCleanupReport r = raise_stable_step(m, o);
  EXPECT_GE(r.off_surface, 1);
  EXPECT_EQ(r.collapses + r.dihedral_collapses + r.flips + r.drops + r.relocations, 0);
  EXPECT_EQ(m.T, before.T);
  EXPECT_EQ(m.F, before.F);
  const TetQuality q = tet_quality(m);
  EXPECT_GE(q.min_dihedral_deg, 12.0);
  EXPECT_NEAR(r.min_dihedral_after, q.min_dihedral_deg, 1e-9);
  EXPECT_GT(q.min_volume, 0.0);
  // Every node (all on the surface here) within the budget of the boundary
  // as it was (brute force over its faces).
  int moved = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    if (m.V.row(i) == before.V.row(i)) continue;
    ++moved;
    const Eigen::Vector3d p = m.V.row(i).transpose();
    double d = INFINITY;
    for (Eigen::Index f = 0; f < before.F.rows(); ++f)
      d = std::min(d, (closest_point_on_triangle(p, before.V.row(before.F(f, 0)).transpose(),
                                                 before.V.row(before.F(f, 1)).transpose(),
                                                 before.V.row(before.F(f, 2)).transpose()) -
                       p).norm());
    EXPECT_LE(d, o.max_off_surface * diagonal * (1 + 1e-9)) << "node " << i;
  }
  EXPECT_GE(moved, 1);
  // Off: nothing moves, the sliver stays.
  o.max_off_surface = 0;
  const StepCleanupReport r_off = raise_stable_step(off, o);
  EXPECT_EQ(r_off.off_surface + r_off.relocations, 0);
  EXPECT_EQ(off.V, before.V);
  EXPECT_LT(tet_quality(off).min_dihedral_deg, 11.0);
}

TEST(TetCleanup, BadOptionsAreRefused) {
  TetMesh m = bcc_block(2, 1.0);
  StepCleanupOptions o;
  o.target_ratio = -1;
  EXPECT_THROW(raise_stable_step(m, o), ParameterError);
  o = {};
  o.poisson = 0.5;
  EXPECT_THROW(raise_stable_step(m, o), ParameterError);
  o = {};
  o.max_relocation_sweeps = -1;
  EXPECT_THROW(raise_stable_step(m, o), ParameterError);
  o = {};
  o.dihedral_volume_change = -0.01;
  EXPECT_THROW(raise_stable_step(m, o), ParameterError);
  o = {};
  o.max_off_surface = -0.001;
  EXPECT_THROW(raise_stable_step(m, o), ParameterError);
}

}  // namespace
}  // namespace icd::mesh
