#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include "mesh/pipeline/pipeline_test_utils.hpp"
#include <icd/mesh/pipeline/repair.hpp>

namespace icd::mesh {
namespace {

using test::closed_and_oriented;
using test::enclosed_volume;

// Expects repair_surface(m) to throw InputError whose message contains every
// fragment; prints the message for the log.
void expect_refused(const SurfaceMesh& m, std::initializer_list<const char*> fragments,
                    const RepairOptions& o = {}) {
  try {
    repair_surface(m, o, "in.off");
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("in.off: ", 0), 0u) << msg;
    for (const char* f : fragments)
      EXPECT_NE(msg.find(f), std::string::npos) << "'" << f << "' not in: " << msg;
    std::cout << "  message: " << msg << "\n";
  }
}

TEST(Repair, CleanSphereIsUnchanged) {
  const SurfaceMesh s = make_icosphere(2);
  const RepairResult r = repair_surface(s);
  EXPECT_EQ(r.mesh.V.rows(), s.V.rows());
  EXPECT_EQ(r.mesh.F.rows(), s.F.rows());
  EXPECT_EQ(r.report.merged_duplicate_vertices + r.report.removed_degenerate_faces +
                r.report.removed_duplicate_faces + r.report.reoriented_faces +
                r.report.holes_filled,
            0);
  EXPECT_FALSE(r.report.reversed_to_outward);
  EXPECT_EQ(r.report.components, 1);
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  EXPECT_NEAR(r.report.volume, enclosed_volume(s.V, s.F), 1e-12);
}

TEST(Repair, FillsSmallHole) {
  const SurfaceMesh s = make_icosphere(3);
  std::set<int> drop;  // the fan of vertex 0 (valence 5): a 5-edge hole
  for (int f = 0; f < s.F.rows(); ++f)
    if ((s.F.row(f).array() == 0).any()) drop.insert(f);
  ASSERT_EQ(drop.size(), 5u);
  const RepairResult r = repair_surface(test::without_faces(s, drop));
  EXPECT_EQ(r.report.holes_filled, 1);
  EXPECT_GE(r.report.hole_faces_added, 3);
  EXPECT_EQ(r.report.removed_unreferenced_vertices, 1);
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  // The patch closes the surface: the volume is within 0.5% of the intact sphere.
  const double intact = enclosed_volume(s.V, s.F);
  EXPECT_NEAR(enclosed_volume(r.mesh.V, r.mesh.F) / intact, 1.0, 5e-3);
  EXPECT_NEAR(r.report.volume, enclosed_volume(r.mesh.V, r.mesh.F), 1e-12);
}

TEST(Repair, ReorientsFlippedFacesAndInvertedSurface) {
  const SurfaceMesh s = make_icosphere(2);
  SurfaceMesh flipped = s;
  int k = 0;
  for (int f = 0; f < s.F.rows(); f += 3, ++k) std::swap(flipped.F(f, 1), flipped.F(f, 2));
  const RepairResult r = repair_surface(flipped);
  const int nf = static_cast<int>(s.F.rows());
  EXPECT_TRUE(r.report.reoriented_faces == k || r.report.reoriented_faces == nf - k)
      << r.report.reoriented_faces;
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  EXPECT_NEAR(enclosed_volume(r.mesh.V, r.mesh.F), enclosed_volume(s.V, s.F), 1e-12);

  SurfaceMesh inverted = s;  // consistently oriented, but inward
  inverted.F.col(1).swap(inverted.F.col(2));
  const RepairResult ri = repair_surface(inverted);
  EXPECT_TRUE(ri.report.reversed_to_outward);
  EXPECT_NEAR(enclosed_volume(ri.mesh.V, ri.mesh.F), enclosed_volume(s.V, s.F), 1e-12);
}

TEST(Repair, MergesDuplicateVerticesAndDropsBadFaces) {
  const SurfaceMesh s = make_torus(1.0, 0.3, 16, 8);
  // Triangle soup: every face has its own three vertices.
  SurfaceMesh soup;
  const int nf = static_cast<int>(s.F.rows());
  soup.V.resize(3 * nf, 3);
  soup.F.resize(nf + 2, 3);
  for (int f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c) {
      soup.V.row(3 * f + c) = s.V.row(s.F(f, c));
      soup.F(f, c) = 3 * f + c;
    }
  soup.F.row(nf) << 3, 4, 5;      // duplicate of face 1
  soup.F.row(nf + 1) << 0, 0, 1;  // repeated vertex: degenerate
  const RepairResult r = repair_surface(soup);
  EXPECT_EQ(r.report.merged_duplicate_vertices, 3 * nf - s.V.rows());
  EXPECT_EQ(r.report.removed_duplicate_faces, 1);
  EXPECT_EQ(r.report.removed_degenerate_faces, 1);
  EXPECT_EQ(r.mesh.V.rows(), s.V.rows());
  EXPECT_EQ(r.mesh.F.rows(), s.F.rows());
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  EXPECT_NEAR(r.report.volume, enclosed_volume(s.V, s.F), 1e-12);
}

TEST(Repair, RefusesLargeHole) {
  const SurfaceMesh s = make_icosphere(3);
  std::set<int> drop;
  for (int f = 0; f < s.F.rows(); ++f)
    if ((s.V.row(s.F(f, 0)) + s.V.row(s.F(f, 1)) + s.V.row(s.F(f, 2)))(2) / 3 > 0.6) drop.insert(f);
  RepairOptions o;
  o.max_hole_diameter = 0.1;
  const SurfaceMesh open = test::without_faces(s, drop);
  expect_refused(open, {"open surface", "1 boundary loop", "edges", "--max-hole-diameter 0.1 of",
                        "to fill every hole: --max-hole-edges"},
                 o);
  // The option the message names fixes it.
  try {
    repair_surface(open, o, "in.off");
  } catch (const InputError& e) {
    const std::string msg = e.what();
    const std::string key = "--max-hole-diameter ";
    const double f = std::stod(msg.substr(msg.rfind(key) + key.size()));
    EXPECT_GT(f, 0.1);
    o.max_hole_diameter = f;
    const RepairResult r = repair_surface(open, o, "in.off");
    EXPECT_EQ(r.report.holes_filled, 1);
    EXPECT_TRUE(closed_and_oriented(r.mesh.F));
    // A hole this wide is reported.
    EXPECT_NE(r.report.to_string().find("WARNING: filled a hole"), std::string::npos);
  }
}

TEST(Repair, RefusesNonManifoldEdge) {
  SurfaceMesh b = make_box_surface({0, 0, 0}, {1, 1, 1});
  // A fin: a third triangle on the box edge between vertices F(0,0) and F(0,1).
  SurfaceMesh m;
  m.V.resize(9, 3);
  m.V << b.V, Eigen::RowVector3d(-1, -1, 3);
  m.F.resize(13, 3);
  m.F << b.F, b.F(0, 0), b.F(0, 1), 8;
  RepairOptions o;
  o.wrap = RepairOptions::Wrap::never;
  expect_refused(m, {"non-manifold edge", "shared by 3 faces", "--wrap fallback"}, o);
}

SurfaceMesh box_with_fin() {
  SurfaceMesh b = make_box_surface({0, 0, 0}, {1, 1, 1});
  SurfaceMesh m;
  m.V.resize(9, 3);
  m.V << b.V, Eigen::RowVector3d(-0.2, -0.2, 1.2);
  m.F.resize(13, 3);
  m.F << b.F, b.F(0, 0), b.F(0, 1), 8;
  return m;
}

TEST(Repair, NonManifoldEdgeIsWrappedByDefault) {
  // The option the refusal above names fixes it (and is the default): the
  // alpha wrap is a closed, oriented surface enclosing the box and its fin.
  const SurfaceMesh m = box_with_fin();
  RepairOptions o;  // the default --wrap fallback, at a coarser alpha (fewer faces: faster)
  o.wrap_alpha = 0.02;
  const RepairResult r = repair_surface(m, o, "in.off");
  EXPECT_EQ(r.report.wrap_cause, 1);
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  EXPECT_EQ(r.report.components, 1);
  // Oracle: the unit box grown by the offset (alpha / 30 of the diagonal)
  // plus a thin shell around the fin; within 3 %.
  EXPECT_NEAR(enclosed_volume(r.mesh.V, r.mesh.F), 1.0, 0.03);
  EXPECT_NEAR(r.report.volume, enclosed_volume(r.mesh.V, r.mesh.F), 1e-9);
  // Every wrap vertex lies near the input: within the bounding box of the
  // box and fin grown by 2 % of the diagonal.
  const double diag = std::sqrt(3.0);
  for (int i = 0; i < r.mesh.V.rows(); ++i) {
    const Eigen::RowVector3d p = r.mesh.V.row(i);
    EXPECT_TRUE((p.array() >= -0.2 - 0.02 * diag).all() && (p.array() <= 1.2 + 0.02 * diag).all())
        << p;
  }
  EXPECT_LE(r.report.wrap_distance, o.max_wrap_distance);
  EXPECT_GT(r.report.wrap_distance, 0.0);  // the offset at least
  EXPECT_NE(r.report.to_string().find("rebuilt the surface by alpha wrapping"), std::string::npos);
  // A wrap limit below what the wrap achieves refuses it, naming --wrap-alpha.
  RepairOptions strict = o;
  strict.max_wrap_distance = 1e-6;
  expect_refused(m, {"non-manifold edge", "alpha wrapping", "--wrap-alpha", "--max-wrap-distance"},
                 strict);
}

TEST(Repair, SplitsNonManifoldVertex) {
  // Two tetrahedra touching at one vertex: every edge is fine, the vertex is not.
  const TetMesh t = make_unit_tet();
  SurfaceMesh m;
  m.V.resize(7, 3);
  m.V << t.V, -t.V.bottomRows(3);
  m.F.resize(8, 3);
  m.F << t.F, t.F;
  for (int f = 4; f < 8; ++f)
    for (int c = 0; c < 3; ++c)
      if (m.F(f, c) != 0) m.F(f, c) += 3;
  // The vertex is split (one copy per fan, moved slightly into its fan); the
  // two tets stay closed and keep their volume.
  const RepairResult r = repair_surface(m, {}, "in.off");
  EXPECT_EQ(r.report.split_nonmanifold_vertices, 1);
  EXPECT_EQ(r.mesh.V.rows(), 8);
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  EXPECT_EQ(r.report.components, 2);
  EXPECT_NEAR(r.report.volume, 2.0 / 6.0, 0.02 * 2.0 / 6.0);
  EXPECT_NE(r.report.to_string().find("split non-manifold vertices: 1"), std::string::npos);
}

TEST(Repair, WeldingThatMakesANonManifoldVertexIsSplit) {
  // Two tets with distinct but coincident tip vertices: the exact-duplicate
  // merge welds them into a non-manifold vertex, which is then split again.
  const TetMesh t = make_unit_tet();
  SurfaceMesh m;
  m.V.resize(8, 3);
  m.V << t.V, -t.V;
  m.F.resize(8, 3);
  m.F << t.F, t.F.array() + 4;
  const RepairResult r = repair_surface(m, {}, "in.off");
  EXPECT_EQ(r.report.merged_duplicate_vertices, 1);
  EXPECT_EQ(r.report.split_nonmanifold_vertices, 1);
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
}

SurfaceMesh two_overlapping_spheres() {
  const SurfaceMesh a = make_icosphere(3);  // 640 faces each
  SurfaceMesh m;
  m.V.resize(2 * a.V.rows(), 3);
  m.V << a.V, a.V.rowwise() + Eigen::RowVector3d(1.0, 0.2, 0.1);
  m.F.resize(2 * a.F.rows(), 3);
  m.F << a.F, a.F.array() + static_cast<int>(a.V.rows());
  return m;
}

TEST(Repair, OverlappingSpheresBecomeTheirUnion) {
  // Two closed unit spheres overlapping: the autorefinement keeps the outer
  // surface of their union (the case where the local repair cut 640
  // faces to 62). Oracle: the union volume 2 V_ball - V_lens of two balls at
  // distance d (lens = pi (2r - d/2)^2 (d + 4r... ) / 12 form below).
  const SurfaceMesh m = two_overlapping_spheres();
  const RepairResult r = repair_surface(m, {}, "in.off");
  EXPECT_GT(r.report.self_intersections_autorefined, 0);
  EXPECT_EQ(r.report.self_intersections_repaired, 0);
  EXPECT_EQ(r.report.components, 1);
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  EXPECT_GT(r.mesh.F.rows(), 1000);
  const double d = Eigen::Vector3d(1.0, 0.2, 0.1).norm(), R = 1.0;
  const double lens = std::numbers::pi * (4 * R + d) * (2 * R - d) * (2 * R - d) / 12.0;
  const double vball = enclosed_volume(make_icosphere(3).V, make_icosphere(3).F);
  const double expected = 2 * vball - lens * vball / (4.0 / 3.0 * std::numbers::pi);
  EXPECT_NEAR(r.report.volume, expected, 0.02 * expected);
}

TEST(Repair, LocalFoldIsNotCutAway) {
  // One sphere with a few vertices pushed through the opposite side: a
  // single component whose repair must keep (nearly) all of its volume.
  SurfaceMesh m = make_icosphere(3);
  const double v0 = enclosed_volume(m.V, m.F);
  int moved = 0;
  for (int i = 0; i < m.V.rows() && moved < 1; ++i)
    if (m.V(i, 2) > 0.99) {
      m.V(i, 2) = -1.2;  // the north pole pokes out through the south pole
      ++moved;
    }
  ASSERT_EQ(moved, 1);
  try {
    const RepairResult r = repair_surface(m, {}, "in.off");
    EXPECT_GT(r.report.volume, 0.9 * v0);
    EXPECT_GT(r.mesh.F.rows(), m.F.rows() / 2);
  } catch (const InputError& e) {  // a refusal is acceptable; a silent cut is not
    std::cout << "  message: " << e.what() << "\n";
  }
}

TEST(Repair, RefusesSelfIntersectionWithCountLocationAndOption) {
  RepairOptions o;
  o.autorefine = false;          // only the local repair, which changes the shape a lot here
  o.max_surface_change = 0.001;  // refused above 0.1 %
  o.wrap = RepairOptions::Wrap::never;
  expect_refused(two_overlapping_spheres(),
                 {"intersects itself", "intersecting face pair", "e.g. faces near",
                  "the local repair", "--wrap fallback"},
                 o);
}

TEST(Repair, UnresolvedSelfIntersectionIsWrapped) {
  // The same case with the option the refusal names: the wrap encloses the
  // union of the two spheres (oracle as in OverlappingSpheresBecomeTheirUnion,
  // plus the offset shell: 3 %).
  RepairOptions o;
  o.autorefine = false;
  o.max_surface_change = 0.001;
  o.wrap = RepairOptions::Wrap::fallback;
  o.wrap_alpha = 0.03;  // coarser than the default: faster
  const RepairResult r = repair_surface(two_overlapping_spheres(), o, "in.off");
  EXPECT_EQ(r.report.wrap_cause, 2);
  EXPECT_EQ(r.report.self_intersections_repaired, 0);
  EXPECT_EQ(r.report.components, 1);
  EXPECT_TRUE(closed_and_oriented(r.mesh.F));
  const double d = Eigen::Vector3d(1.0, 0.2, 0.1).norm(), R = 1.0;
  const double lens = std::numbers::pi * (4 * R + d) * (2 * R - d) * (2 * R - d) / 12.0;
  const double vball = enclosed_volume(make_icosphere(3).V, make_icosphere(3).F);
  const double expected = 2 * vball - lens * vball / (4.0 / 3.0 * std::numbers::pi);
  EXPECT_NEAR(r.report.volume, expected, 0.03 * expected);
}

TEST(Repair, WrapNamesRoundTripAndABadNameNamesTheField) {
  for (auto w : {RepairOptions::Wrap::never, RepairOptions::Wrap::fallback,
                 RepairOptions::Wrap::always})
    EXPECT_EQ(parse_wrap(to_string(w)), w);
  try {
    parse_wrap("sometimes", "--wrap");
    ADD_FAILURE() << "no exception";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("--wrap"), std::string::npos) << e.what();
  }
}

TEST(Repair, RefusesZeroVolume) {
  SurfaceMesh flat = make_icosphere(2);
  flat.V.col(2).setZero();  // squashed into the plane z = 0
  expect_refused(flat, {"zero volume"});
}

TEST(Repair, RefusesBadIndicesAndCoordinates) {
  SurfaceMesh s = make_icosphere(1);
  s.F(7, 2) = 1000;
  expect_refused(s, {"face 7", "1000"});
  s = make_icosphere(1);
  s.V(3, 1) = std::nan("");
  expect_refused(s, {"vertex 3", "non-finite"});
}

}  // namespace
}  // namespace icd::mesh
