// Each reader on good files written by the test itself (independent encoders:
// printf for text, explicit byte packing for binary), compared exactly with
// the generated primitives.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>

#include "io_test_util.hpp"
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/surface_reader.hpp>

namespace icd {
namespace {

using test::g17;
using test::TempDir;
using test::write_bytes;

void expect_same(const SurfaceMesh& a, const SurfaceMesh& b) {
  ASSERT_EQ(a.V.rows(), b.V.rows());
  ASSERT_EQ(a.F.rows(), b.F.rows());
  EXPECT_TRUE(a.V == b.V);  // bit-exact
  EXPECT_TRUE(a.F == b.F);
}

std::string off_text(const SurfaceMesh& m) {
  std::string s = "OFF\n# a comment\n" + std::to_string(m.V.rows()) + " " +
                  std::to_string(m.F.rows()) + " 0\n\n";
  for (int i = 0; i < m.V.rows(); ++i)
    s += g17(m.V(i, 0)) + " " + g17(m.V(i, 1)) + "\t" + g17(m.V(i, 2)) + "\r\n";
  for (int f = 0; f < m.F.rows(); ++f)
    s += "3 " + std::to_string(m.F(f, 0)) + " " + std::to_string(m.F(f, 1)) + " " +
         std::to_string(m.F(f, 2)) + "\n";
  return s;
}

std::string obj_text(const SurfaceMesh& m) {
  std::string s = "# generated\no thing\n";
  for (int i = 0; i < m.V.rows(); ++i)
    s += "v " + g17(m.V(i, 0)) + " " + g17(m.V(i, 1)) + " " + g17(m.V(i, 2)) + "\n";
  s += "vn 0 0 1\nvt 0.5 0.5\n";
  for (int f = 0; f < m.F.rows(); ++f) {
    // Alternate the corner syntaxes: i, i/t, i//n, i/t/n.
    const char* suffix[] = {"", "/1", "//1", "/1/1"};
    s += "f";
    for (int c = 0; c < 3; ++c) {
      s += ' ';
      s += std::to_string(m.F(f, c) + 1);
      s += suffix[(f + c) % 4];
    }
    s += "\n";
  }
  return s;
}

TEST(SurfaceReaders, OffMatchesPrimitive) {
  TempDir dir;
  const SurfaceMesh m = make_icosphere(2, 1.5);
  ReadReport report;
  expect_same(read_surface_mesh(write_bytes(dir / "ico.off", off_text(m)), &report), m);
  EXPECT_EQ(report.format, "OFF");
  EXPECT_EQ(report.vertices, m.V.rows());
  EXPECT_EQ(report.triangles, m.F.rows());
  EXPECT_EQ(report.polygons_triangulated, 0);
  EXPECT_TRUE(report.notes.empty());
  // Upper-case extension and counts on the header line.
  std::string one_line = off_text(m);
  one_line.replace(0, one_line.find("0\n\n") + 1,
                   "OFF " + std::to_string(m.V.rows()) + " " + std::to_string(m.F.rows()) + " 0");
  expect_same(read_surface_mesh(write_bytes(dir / "ICO.OFF", one_line)), m);
}

TEST(SurfaceReaders, ColouredOffVariantIgnoresExtraColumns) {
  TempDir dir;
  const SurfaceMesh m = make_box_surface({0, 0, 0}, {1, 2, 3});
  std::string s = "COFF\n8 12 0\n";
  for (int i = 0; i < 8; ++i)
    s += g17(m.V(i, 0)) + " " + g17(m.V(i, 1)) + " " + g17(m.V(i, 2)) + " 255 0 0 255\n";
  for (int f = 0; f < 12; ++f)
    s += "3 " + std::to_string(m.F(f, 0)) + " " + std::to_string(m.F(f, 1)) + " " +
         std::to_string(m.F(f, 2)) + " 0.5 0.5 0.5\n";
  expect_same(read_surface_mesh(write_bytes(dir / "box.off", s)), m);
}

TEST(SurfaceReaders, ObjMatchesPrimitiveWithAllCornerSyntaxes) {
  TempDir dir;
  const SurfaceMesh m = make_torus(2.0, 0.5, 12, 8);
  ReadReport report;
  expect_same(read_surface_mesh(write_bytes(dir / "torus.obj", obj_text(m)), &report), m);
  EXPECT_EQ(report.format, "OBJ");
}

TEST(SurfaceReaders, ObjNegativeIndicesAreRelative) {
  TempDir dir;
  const std::string s = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1\nf 1 -3 -1\n";
  const SurfaceMesh m = read_surface_mesh(write_bytes(dir / "rel.obj", s));
  ASSERT_EQ(m.F.rows(), 2);
  EXPECT_EQ(m.F.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(m.F.row(1), Eigen::RowVector3i(0, 1, 3));
}

// --- PLY -------------------------------------------------------------------

template <class T>
void put(std::string& out, T value, bool big_endian) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  const bool native_big = std::endian::native == std::endian::big;
  if (big_endian != native_big)
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

// A binary PLY with distracting extra properties and elements: vertex has
// (double x, uchar red, double y, double z, float confidence), face has
// (uchar flags, list <count_t> int <name>, list uchar float texcoord),
// plus an "edge" element before the faces.
template <class CountT>
std::string binary_ply(const SurfaceMesh& m, bool big, const std::string& list_name,
                       const std::string& count_type) {
  std::string s = "ply\nformat ";
  s += big ? "binary_big_endian" : "binary_little_endian";
  s += " 1.0\ncomment made by a test\nelement vertex " + std::to_string(m.V.rows()) +
       "\nproperty double x\nproperty uchar red\nproperty double y\nproperty double z\n"
       "property float confidence\nelement edge 2\nproperty int vertex1\nproperty int vertex2\n"
       "element face " +
       std::to_string(m.F.rows()) + "\nproperty uchar flags\nproperty list " + count_type +
       " int " + list_name + "\nproperty list uchar float texcoord\nend_header\n";
  for (int i = 0; i < m.V.rows(); ++i) {
    put<double>(s, m.V(i, 0), big);
    put<uint8_t>(s, 7, big);
    put<double>(s, m.V(i, 1), big);
    put<double>(s, m.V(i, 2), big);
    put<float>(s, 0.25f, big);
  }
  for (int e = 0; e < 2; ++e) {
    put<int32_t>(s, e, big);
    put<int32_t>(s, e + 1, big);
  }
  for (int f = 0; f < m.F.rows(); ++f) {
    put<uint8_t>(s, 1, big);
    put<CountT>(s, 3, big);
    for (int c = 0; c < 3; ++c) put<int32_t>(s, m.F(f, c), big);
    const int ntex = f % 3;  // varying list length must be skipped correctly
    put<uint8_t>(s, static_cast<uint8_t>(ntex), big);
    for (int k = 0; k < ntex; ++k) put<float>(s, 0.5f, big);
  }
  return s;
}

TEST(SurfaceReaders, PlyBinaryLittleEndian) {
  TempDir dir;
  const SurfaceMesh m = make_icosphere(1, 0.7);
  ReadReport report;
  expect_same(
      read_surface_mesh(
          write_bytes(dir / "le.ply", binary_ply<uint8_t>(m, false, "vertex_indices", "uchar")),
          &report),
      m);
  EXPECT_EQ(report.format, "PLY binary_little_endian");
}

TEST(SurfaceReaders, PlyBinaryBigEndianWithIntCountsAndVertexIndex) {
  TempDir dir;
  const SurfaceMesh m = make_icosphere(1, 0.7);
  ReadReport report;
  expect_same(read_surface_mesh(
                  write_bytes(dir / "be.PLY", binary_ply<int32_t>(m, true, "vertex_index", "int")),
                  &report),
              m);
  EXPECT_EQ(report.format, "PLY binary_big_endian");
}

TEST(SurfaceReaders, PlyBinaryFloatCoordinates) {
  TempDir dir;
  SurfaceMesh m = make_icosphere(1, 1.0);
  m.V = m.V.cast<float>().cast<double>();  // what a float file can hold exactly
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(m.V.rows()) +
      "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
      std::to_string(m.F.rows()) + "\nproperty list uchar uint vertex_indices\nend_header\n";
  for (int i = 0; i < m.V.rows(); ++i)
    for (int c = 0; c < 3; ++c) put<float>(s, static_cast<float>(m.V(i, c)), false);
  for (int f = 0; f < m.F.rows(); ++f) {
    put<uint8_t>(s, 3, false);
    for (int c = 0; c < 3; ++c) put<uint32_t>(s, static_cast<uint32_t>(m.F(f, c)), false);
  }
  expect_same(read_surface_mesh(write_bytes(dir / "f.ply", s)), m);
}

TEST(SurfaceReaders, PlyAscii) {
  TempDir dir;
  const SurfaceMesh m = make_torus(1.0, 0.25, 6, 5);
  std::string s =
      "ply\r\nformat ascii 1.0\r\nobj_info test\r\nelement vertex " + std::to_string(m.V.rows()) +
      "\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n"
      "property list uchar float extra\r\nelement face " +
      std::to_string(m.F.rows()) + "\r\nproperty list uchar int vertex_indices\r\nend_header\r\n";
  for (int i = 0; i < m.V.rows(); ++i)
    s += g17(m.V(i, 0)) + " " + g17(m.V(i, 1)) + " " + g17(m.V(i, 2)) + " 2 0.5 1e-3\r\n";
  for (int f = 0; f < m.F.rows(); ++f)
    s += "3 " + std::to_string(m.F(f, 0)) + " " + std::to_string(m.F(f, 1)) + " " +
         std::to_string(m.F(f, 2)) + "\r\n";
  ReadReport report;
  // ASCII PLY declared as float but written with 17 digits reads back exactly as double.
  expect_same(read_surface_mesh(write_bytes(dir / "a.ply", s), &report), m);
  EXPECT_EQ(report.format, "PLY ascii");
}

// --- STL -------------------------------------------------------------------

// One STL triangle soup per face of `m`, with float-rounded coordinates.
std::string binary_stl(const SurfaceMesh& m, const std::string& header80) {
  std::string s = header80;
  s.resize(80, ' ');
  put<uint32_t>(s, static_cast<uint32_t>(m.F.rows()), false);
  for (int f = 0; f < m.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) put<float>(s, 0.0f, false);
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) put<float>(s, static_cast<float>(m.V(m.F(f, k), c)), false);
    put<uint16_t>(s, 0, false);
  }
  return s;
}

std::string ascii_stl(const SurfaceMesh& m) {
  std::string s = "solid test object\n";
  for (int f = 0; f < m.F.rows(); ++f) {
    s += "  facet normal 0 0 1\n    outer loop\n";
    for (int k = 0; k < 3; ++k) {
      s += "      vertex";
      for (int c = 0; c < 3; ++c) {
        s += ' ';
        s += g17(static_cast<float>(m.V(m.F(f, k), c)));
      }
      s += "\n";
    }
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid test object\n";
}

// Welding oracle: the icosphere has no two vertices at the same position, so
// the welded mesh has the same vertex count and each triangle the same corner
// coordinates (float-rounded) as the original.
void expect_welded_equivalent(const SurfaceMesh& got, const SurfaceMesh& m) {
  ASSERT_EQ(got.V.rows(), m.V.rows());
  ASSERT_EQ(got.F.rows(), m.F.rows());
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(got.V(got.F(f, k), c), static_cast<double>(static_cast<float>(m.V(m.F(f, k), c))))
            << "face " << f;
}

TEST(SurfaceReaders, StlBinaryWeldsCorners) {
  TempDir dir;
  const SurfaceMesh m = make_icosphere(2);
  ReadReport report;
  // A header that starts with "solid" must not fool the format detection.
  const SurfaceMesh got =
      read_surface_mesh(write_bytes(dir / "b.stl", binary_stl(m, "solid but binary")), &report);
  expect_welded_equivalent(got, m);
  EXPECT_EQ(report.format, "STL binary");
  EXPECT_EQ(report.corners_welded, 3 * m.F.rows() - m.V.rows());
}

TEST(SurfaceReaders, StlAsciiWeldsCorners) {
  TempDir dir;
  const SurfaceMesh m = make_icosphere(2);
  ReadReport report;
  const SurfaceMesh got = read_surface_mesh(write_bytes(dir / "a.stl", ascii_stl(m)), &report);
  expect_welded_equivalent(got, m);
  EXPECT_EQ(report.format, "STL ascii");
  EXPECT_EQ(report.corners_welded, 3 * m.F.rows() - m.V.rows());
}

TEST(SurfaceReaders, StlWeldsSignedZeros) {
  TempDir dir;
  const std::string s =
      "solid z\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex -0 -0.0 0\nvertex 0 1 0\n"
      "vertex 1 0 -0\nendloop\nendfacet\nendsolid z\n";
  const SurfaceMesh got = read_surface_mesh(write_bytes(dir / "z.stl", s));
  EXPECT_EQ(got.V.rows(), 3);
}

// --- Polygons ----------------------------------------------------------------

TEST(SurfaceReaders, PolygonsAreFanTriangulatedWithANote) {
  TempDir dir;
  // A unit cube written as 6 quads (OFF) and as 6 quads (OBJ) and one pentagon.
  const std::string verts = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
  const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  std::string off = "OFF\n8 6 12\n" + verts, obj;
  for (const auto& q : quads)
    off += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
           " " + std::to_string(q[3]) + "\n";
  for (size_t p = 0; p < verts.size();) {
    const size_t e = verts.find('\n', p);
    obj += "v " + verts.substr(p, e - p + 1);
    p = e + 1;
  }
  for (const auto& q : quads)
    obj += "f " + std::to_string(q[0] + 1) + " " + std::to_string(q[1] + 1) + " " +
           std::to_string(q[2] + 1) + " " + std::to_string(q[3] + 1) + "\n";
  for (const auto& [name, text] : {std::pair{"cube.off", off}, std::pair{"cube.obj", obj}}) {
    ReadReport report;
    const SurfaceMesh m = read_surface_mesh(write_bytes(dir / name, text), &report);
    ASSERT_EQ(m.F.rows(), 12) << name;
    EXPECT_EQ(report.polygons, 6);
    EXPECT_EQ(report.polygons_triangulated, 6);
    ASSERT_EQ(report.notes.size(), 1u);
    EXPECT_NE(report.notes[0].find("triangulated"), std::string::npos);
    // Fan: quad (a b c d) -> (a b c), (a c d).
    for (int q = 0; q < 6; ++q) {
      EXPECT_EQ(m.F.row(2 * q), Eigen::RowVector3i(quads[q][0], quads[q][1], quads[q][2]));
      EXPECT_EQ(m.F.row(2 * q + 1), Eigen::RowVector3i(quads[q][0], quads[q][2], quads[q][3]));
    }
    // Oracle: the fan preserves the enclosed volume of the unit cube.
    double vol = 0;
    for (int f = 0; f < m.F.rows(); ++f)
      vol += m.V.row(m.F(f, 0)).dot(m.V.row(m.F(f, 1)).cross(m.V.row(m.F(f, 2)))) / 6.0;
    EXPECT_DOUBLE_EQ(vol, 1.0) << name;
  }
}

TEST(SurfaceReaders, PlyPolygonsAreTriangulated) {
  TempDir dir;
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty double x\nproperty double y\n"
      "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0.5 1.5 0\n0 1 0\n5 0 1 2 3 4\n";
  ReadReport report;
  const SurfaceMesh m = read_surface_mesh(write_bytes(dir / "penta.ply", s), &report);
  ASSERT_EQ(m.F.rows(), 3);
  EXPECT_EQ(report.polygons_triangulated, 1);
  EXPECT_EQ(m.F.row(2), Eigen::RowVector3i(0, 3, 4));
}

TEST(SurfaceReaders, NotesForIgnoredData) {
  TempDir dir;
  ReadReport report;
  read_surface_mesh(
      write_bytes(dir / "a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nfoo 1\nfoo 2\nf 1 2 3\n"), &report);
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_NE(report.notes[0].find("ignored 2 lines with unknown keyword 'foo'"), std::string::npos)
      << report.notes[0];
  // PLY: elements in any order (faces before vertices), trailing data warned about.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
      "element vertex 3\nproperty double x\nproperty double y\nproperty double z\nend_header\n"
      "3 2 1 0\n0 0 0\n1 0 0\n0 1 0\n7 7 7\n";
  const SurfaceMesh m = read_surface_mesh(write_bytes(dir / "b.ply", ply), &report);
  ASSERT_EQ(m.F.rows(), 1);
  EXPECT_EQ(m.F.row(0), Eigen::RowVector3i(2, 1, 0));
  EXPECT_EQ(m.V.row(1), Eigen::RowVector3d(1, 0, 0));
  EXPECT_TRUE(report.notes.empty());
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("ignored data after the last element"), std::string::npos);
  // OFF: trailing comments and a comment-only line between vertices.
  const SurfaceMesh off = read_surface_mesh(write_bytes(
      dir / "c.off", "OFF # header\n3 1 0\n0 0 0 # v0\n# between\n1 0 0\n0 1 0\n3 0 1 2 # f\n"));
  EXPECT_EQ(off.V.row(2), Eigen::RowVector3d(0, 1, 0));
}

}  // namespace
}  // namespace icd
