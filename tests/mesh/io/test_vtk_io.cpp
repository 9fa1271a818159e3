// VTU/PVD writers and the VTU reader: exact round trips through our reader
// and through meshio (an independent reader), validation errors, and
// atomic writes.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/vtk_writer.hpp>
#include <icd/mesh/io/vtu_reader.hpp>

namespace icd {
namespace {

using test::expect_contains_all;
using test::input_error_message;
using test::TempDir;
using test::write_bytes;

TetMesh small_tet_mesh() {
  BoxMeshOptions o;
  o.size = {1.0, 0.3, 0.7};
  o.min_corner = {-0.1, 0.2, 1.0 / 3.0};
  o.nx = 3;
  o.ny = 2;
  o.nz = 2;
  return make_box_tet_mesh(o);
}

SphereSet random_spheres(int n) {
  std::mt19937 rng(0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SphereSet s;
  s.centers.resize(n, 3);
  s.radii.resize(n);
  for (int i = 0; i < n; ++i) {
    s.centers.row(i) << u(rng), u(rng), u(rng);
    s.radii[i] = 0.5 * (u(rng) + 1.0);
  }
  s.radii[0] = 0.0;  // a zero radius is allowed
  return s;
}

Eigen::MatrixXd random_matrix(Eigen::Index rows, Eigen::Index cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1e3);
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = n(rng);
  return m;
}

TEST(VtkIo, OwnReaderRoundTripsExactly) {
  TempDir dir;
  const TetMesh tets = small_tet_mesh();
  const std::vector<PointDataArray> pd = {
      {"displacement", random_matrix(tets.V.rows(), 3, 1)},
      {"a <weird> & \"name\"", random_matrix(tets.V.rows(), 1, 2)}};
  write_vtu_tet_mesh(dir / "tets.vtu", tets, pd);
  const TetMesh t2 = read_vtu_tet_mesh(dir / "tets.vtu");
  EXPECT_TRUE(t2.V == tets.V);
  EXPECT_TRUE(t2.T == tets.T);
  EXPECT_TRUE(t2.F == tets.F);
  const VtuData raw = read_vtu(dir / "tets.vtu");
  ASSERT_EQ(raw.point_data.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(raw.point_data[k].name, pd[k].name);
    EXPECT_TRUE(raw.point_data[k].values == pd[k].values);
  }

  const SurfaceMesh ico = make_icosphere(2, 0.3);
  write_vtu_surface_mesh(dir / "ico.vtu", ico);
  const SurfaceMesh s2 = read_vtu_surface_mesh(dir / "ico.vtu");
  EXPECT_TRUE(s2.V == ico.V);
  EXPECT_TRUE(s2.F == ico.F);

  const SphereSet spheres = random_spheres(17);
  write_vtu_sphere_set(dir / "spheres.vtu", spheres,
                       std::vector<PointDataArray>{{"level", random_matrix(17, 1, 3)}});
  const SphereSet sp2 = read_vtu_sphere_set(dir / "spheres.vtu");
  EXPECT_TRUE(sp2.centers == spheres.centers);
  EXPECT_TRUE(sp2.radii == spheres.radii);
  EXPECT_FALSE(std::filesystem::exists(dir / "spheres.vtu.part"));
}

// What meshio reports for one file.
struct MeshioView {
  int64_t num_points = -1;
  std::map<std::string, std::vector<int64_t>> cells;                      // type -> connectivity
  std::vector<double> points;                                             // row-major
  std::map<std::string, std::pair<int, std::vector<double>>> point_data;  // name -> (k, values)
  std::map<std::string, std::pair<int, std::vector<double>>> cell_data;   // name -> (k, values)
};

bool meshio_available() {
  return std::system("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") == 0;
}

std::map<std::string, MeshioView> read_with_meshio(
    const std::vector<std::filesystem::path>& files) {
  std::string cmd =
      "/usr/bin/python3 -c '\n"
      "import sys, meshio\n"
      "for f in sys.argv[1:]:\n"
      "    m = meshio.read(f)\n"
      "    print(\"FILE\", f, len(m.points))\n"
      "    for c in m.cells:\n"
      "        print(\"CELLS\", c.type, \" \".join(str(int(i)) for i in c.data.ravel()))\n"
      "    print(\"POINTS\", \" \".join(repr(float(x)) for x in m.points.ravel()))\n"
      "    for k, v in m.point_data.items():\n"
      "        print(\"PD\", k.replace(\" \", \"_\"), v.shape[1] if v.ndim > 1 else 1,\n"
      "              \" \".join(repr(float(x)) for x in v.ravel()))\n"
      "    for k, blocks in m.cell_data.items():\n"
      "        v = blocks[0]\n"
      "        print(\"CD\", k.replace(\" \", \"_\"), v.shape[1] if v.ndim > 1 else 1,\n"
      "              \" \".join(repr(float(x)) for x in v.ravel()))\n"
      "'";
  for (const auto& f : files) cmd += " '" + f.string() + "'";
  cmd += " 2>&1";
  std::string out;
  if (std::FILE* p = ::popen(cmd.c_str(), "r")) {
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    EXPECT_EQ(::pclose(p), 0) << out;
  }
  std::map<std::string, MeshioView> views;
  std::istringstream lines(out);
  std::string line;
  MeshioView* cur = nullptr;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    std::string tag;
    in >> tag;
    if (tag == "FILE") {
      std::string f;
      in >> f;
      cur = &views[f];
      in >> cur->num_points;
    } else if (cur && tag == "CELLS") {
      std::string type;
      in >> type;
      int64_t i;
      while (in >> i) cur->cells[type].push_back(i);
    } else if (cur && tag == "POINTS") {
      double x;
      while (in >> x) cur->points.push_back(x);
    } else if (cur && (tag == "PD" || tag == "CD")) {
      std::string name;
      int k;
      in >> name >> k;
      auto& [kk, values] = (tag == "PD" ? cur->point_data : cur->cell_data)[name];
      kk = k;
      double x;
      while (in >> x) values.push_back(x);
    } else if (line.find("cannot handle (type 2)") != std::string::npos) {
      // meshio's note on an empty sphere set's empty poly-vertex cell.
    } else {
      ADD_FAILURE() << "unexpected meshio output: " << line;
    }
  }
  return views;
}

template <class Mat>
std::vector<double> row_major(const Mat& m) {
  std::vector<double> v;
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index c = 0; c < m.cols(); ++c) v.push_back(static_cast<double>(m(i, c)));
  return v;
}

TEST(VtkIo, MeshioReadsWhatWeWrite) {
  if (!meshio_available()) GTEST_SKIP() << "/usr/bin/python3 cannot import meshio";
  TempDir dir;
  const TetMesh tets = small_tet_mesh();
  const Eigen::MatrixXd disp = random_matrix(tets.V.rows(), 3, 4);
  write_vtu_tet_mesh(dir / "tets.vtu", tets, std::vector<PointDataArray>{{"displacement", disp}});
  const SurfaceMesh torus = make_torus(1.0, 0.3, 9, 7);
  write_vtu_surface_mesh(dir / "torus.vtu", torus);
  const SphereSet spheres = random_spheres(23);
  write_vtu_sphere_set(dir / "spheres.vtu", spheres);

  auto views = read_with_meshio({dir / "tets.vtu", dir / "torus.vtu", dir / "spheres.vtu"});
  ASSERT_EQ(views.size(), 3u);

  const MeshioView& t = views[(dir / "tets.vtu").string()];
  EXPECT_EQ(t.num_points, tets.V.rows());
  EXPECT_EQ(t.points, row_major(tets.V));  // exact: repr() and to_chars both round-trip
  ASSERT_EQ(t.cells.size(), 1u);
  ASSERT_TRUE(t.cells.count("tetra"));
  const std::vector<int64_t> tet_conn(tets.T.data(), tets.T.data() + tets.T.size());
  EXPECT_EQ(t.cells.at("tetra"), tet_conn);
  ASSERT_TRUE(t.point_data.count("displacement"));
  EXPECT_EQ(t.point_data.at("displacement").first, 3);
  EXPECT_EQ(t.point_data.at("displacement").second, row_major(disp));

  const MeshioView& s = views[(dir / "torus.vtu").string()];
  EXPECT_EQ(s.num_points, torus.V.rows());
  EXPECT_EQ(s.points, row_major(torus.V));
  ASSERT_TRUE(s.cells.count("triangle"));
  const std::vector<int64_t> tri_conn(torus.F.data(), torus.F.data() + torus.F.size());
  EXPECT_EQ(s.cells.at("triangle"), tri_conn);

  const MeshioView& p = views[(dir / "spheres.vtu").string()];
  EXPECT_EQ(p.num_points, 23);
  EXPECT_EQ(p.points, row_major(spheres.centers));
  ASSERT_TRUE(p.cells.count("vertex"));
  EXPECT_EQ(p.cells.at("vertex").size(), 23u);
  ASSERT_TRUE(p.point_data.count("radius"));
  EXPECT_EQ(p.point_data.at("radius").second, row_major(spheres.radii));
}

// The binary (raw appended) encoding: meshio reads the same values, point
// and cell data, as written; an empty sphere set is a valid file; and the
// binary file is smaller than the ASCII one.
TEST(VtkIo, MeshioReadsBinaryFilesAndCellData) {
  if (!meshio_available()) GTEST_SKIP() << "/usr/bin/python3 cannot import meshio";
  TempDir dir;
  const TetMesh tets = small_tet_mesh();
  const Eigen::MatrixXd disp = random_matrix(tets.V.rows(), 3, 5);
  const Eigen::MatrixXd vol = random_matrix(tets.T.rows(), 1, 6);
  VtuOptions bin;
  bin.encoding = VtuEncoding::Binary;
  bin.cell_data = {{"volume_ratio", vol}};
  write_vtu_tet_mesh(dir / "tets.vtu", tets, std::vector<PointDataArray>{{"displacement", disp}},
                     bin);
  VtuOptions ascii = bin;
  ascii.encoding = VtuEncoding::Ascii;
  write_vtu_tet_mesh(dir / "tets_ascii.vtu", tets,
                     std::vector<PointDataArray>{{"displacement", disp}}, ascii);
  EXPECT_LT(std::filesystem::file_size(dir / "tets.vtu"),
            std::filesystem::file_size(dir / "tets_ascii.vtu"));
  const SurfaceMesh torus = make_torus(1.0, 0.3, 9, 7);
  VtuOptions plain_bin;
  plain_bin.encoding = VtuEncoding::Binary;
  write_vtu_surface_mesh(dir / "torus.vtu", torus, {}, plain_bin);
  const SphereSet spheres = random_spheres(23);
  write_vtu_sphere_set(dir / "spheres.vtu", spheres,
                       std::vector<PointDataArray>{{"level", random_matrix(23, 1, 7)}}, plain_bin);
  // 570 spheres with two arrays: in data order, meshio 5's base64 offset of
  // an array equals a later array's raw offset (it then read the wrong one).
  const SphereSet tree = random_spheres(570);
  const std::vector<PointDataArray> tree_arrays = {{"level", random_matrix(570, 1, 8)},
                                                   {"leaf", random_matrix(570, 1, 9)}};
  write_vtu_sphere_set(dir / "tree.vtu", tree, tree_arrays, plain_bin);
  const SphereSet none{MatX3d(0, 3), Eigen::VectorXd(0)};
  write_vtu_sphere_set(dir / "empty.vtu", none,
                       std::vector<PointDataArray>{{"level", Eigen::MatrixXd(0, 1)}}, plain_bin);
  write_vtu_sphere_set(dir / "empty_ascii.vtu", none);

  auto views = read_with_meshio({dir / "tets.vtu", dir / "tets_ascii.vtu", dir / "torus.vtu",
                                 dir / "spheres.vtu", dir / "empty.vtu", dir / "empty_ascii.vtu",
                                 dir / "tree.vtu"});
  ASSERT_EQ(views.size(), 7u);
  const MeshioView& tr = views[(dir / "tree.vtu").string()];
  EXPECT_EQ(tr.points, row_major(tree.centers));
  ASSERT_TRUE(tr.cells.count("vertex"));
  EXPECT_EQ(tr.cells.at("vertex").size(), 570u);
  for (const PointDataArray& a : tree_arrays) {
    ASSERT_TRUE(tr.point_data.count(a.name)) << a.name;
    EXPECT_EQ(tr.point_data.at(a.name).second, row_major(a.values)) << a.name;
  }
  for (const char* name : {"tets.vtu", "tets_ascii.vtu"}) {
    SCOPED_TRACE(name);
    const MeshioView& t = views[(dir / name).string()];
    EXPECT_EQ(t.points, row_major(tets.V));
    const std::vector<int64_t> tet_conn(tets.T.data(), tets.T.data() + tets.T.size());
    ASSERT_TRUE(t.cells.count("tetra"));
    EXPECT_EQ(t.cells.at("tetra"), tet_conn);
    ASSERT_TRUE(t.point_data.count("displacement"));
    EXPECT_EQ(t.point_data.at("displacement").second, row_major(disp));
    ASSERT_TRUE(t.cell_data.count("volume_ratio"));
    EXPECT_EQ(t.cell_data.at("volume_ratio").second, row_major(vol));
  }
  const MeshioView& s = views[(dir / "torus.vtu").string()];
  EXPECT_EQ(s.points, row_major(torus.V));
  ASSERT_TRUE(s.cells.count("triangle"));
  EXPECT_EQ(s.cells.at("triangle"),
            std::vector<int64_t>(torus.F.data(), torus.F.data() + torus.F.size()));
  const MeshioView& p = views[(dir / "spheres.vtu").string()];
  EXPECT_EQ(p.points, row_major(spheres.centers));
  ASSERT_TRUE(p.point_data.count("radius"));
  EXPECT_EQ(p.point_data.at("radius").second, row_major(spheres.radii));
  for (const char* name : {"empty.vtu", "empty_ascii.vtu"}) {
    SCOPED_TRACE(name);
    EXPECT_EQ(views[(dir / name).string()].num_points, 0);
  }
}

TEST(VtkIo, PvdListsPartsOfOneStep) {
  TempDir dir;
  write_pvd(dir / "run.pvd", std::vector<PvdEntry>{{0.5, "a.vtu", 0}, {0.5, "b.vtu", 3}});
  std::ifstream in(dir / "run.pvd");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  expect_contains_all(text, {"part=\"0\" file=\"a.vtu\"", "part=\"3\" file=\"b.vtu\""});
  EXPECT_THROW(write_pvd(dir / "bad.pvd", std::vector<PvdEntry>{{0.0, "a.vtu", -1}}),
               ParameterError);
}

TEST(VtkIo, PvdListsTheSteps) {
  TempDir dir;
  const std::vector<PvdEntry> steps = {
      {0.0, "frame_0000.vtu"}, {0.01, "frame_0001.vtu"}, {0.025, "sub dir/f&2.vtu"}};
  write_pvd(dir / "run.pvd", steps);
  std::ifstream in(dir / "run.pvd");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  expect_contains_all(text, {"type=\"Collection\"", "timestep=\"0.01\"", "file=\"frame_0001.vtu\"",
                             "file=\"sub dir/f&amp;2.vtu\""});
  if (!meshio_available()) return;  // the XML check below needs /usr/bin/python3
  const std::string cmd =
      "/usr/bin/python3 -c 'import sys, xml.etree.ElementTree as E\n"
      "for d in E.parse(sys.argv[1]).getroot().iter(\"DataSet\"):\n"
      "    print(repr(float(d.get(\"timestep\"))), d.get(\"file\"))' '" +
      (dir / "run.pvd").string() + "'";
  std::string out;
  if (std::FILE* p = ::popen(cmd.c_str(), "r")) {
    char buf[1024];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    ::pclose(p);
  }
  EXPECT_EQ(out, "0.0 frame_0000.vtu\n0.01 frame_0001.vtu\n0.025 sub dir/f&2.vtu\n");
}

TEST(VtkIo, WriterRejectsBadData) {
  TempDir dir;
  const SurfaceMesh ico = make_icosphere(0);
  const auto path = dir / "bad.vtu";
  const auto expect_param_error = [&](const std::function<void()>& fn, const std::string& part) {
    try {
      fn();
      ADD_FAILURE() << "no exception, expected: " << part;
    } catch (const ParameterError& e) {
      expect_contains_all(e.what(), {"bad.vtu", part});
    }
    EXPECT_FALSE(std::filesystem::exists(path));
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.vtu.part"));
  };
  SurfaceMesh nan_mesh = ico;
  nan_mesh.V(5, 1) = std::nan("");
  expect_param_error([&] { write_vtu_surface_mesh(path, nan_mesh); }, "vertex row 5");
  SurfaceMesh bad_index = ico;
  bad_index.F(3, 2) = 12;
  expect_param_error([&] { write_vtu_surface_mesh(path, bad_index); }, "face 3");
  expect_param_error(
      [&] {
        write_vtu_surface_mesh(path, ico,
                               std::vector<PointDataArray>{{"v", Eigen::MatrixXd::Zero(11, 3)}});
      },
      "'v' is 11 x 3");
  expect_param_error(
      [&] {
        write_vtu_surface_mesh(path, ico,
                               std::vector<PointDataArray>{{"v", Eigen::MatrixXd::Zero(12, 1)},
                                                           {"v", Eigen::MatrixXd::Zero(12, 1)}});
      },
      "used twice");
  SphereSet s = random_spheres(4);
  expect_param_error(
      [&] {
        write_vtu_sphere_set(path, s,
                             std::vector<PointDataArray>{{"radius", Eigen::MatrixXd::Zero(4, 1)}});
      },
      "'radius' is used twice");
  s.radii[2] = -1.0;
  expect_param_error([&] { write_vtu_sphere_set(path, s); }, "sphere 2");
  TetMesh t = make_unit_tet();
  t.T(0, 3) = -1;
  expect_param_error([&] { write_vtu_tet_mesh(path, t); }, "tet 0");
  expect_param_error(
      [&] {
        write_pvd(dir / "bad.vtu", std::vector<PvdEntry>{{std::nan(""), "a.vtu"}});
      },
      "non-finite time");
}

TEST(VtkIo, FailedWriteLeavesNoPartialOutput) {
  TempDir dir;
  const SurfaceMesh ico = make_icosphere(0);
  // Missing parent folder.
  std::string msg = input_error_message([&] { write_vtu_surface_mesh(dir / "no/such.vtu", ico); });
  expect_contains_all(msg, {"such.vtu", "cannot write"});
  // The target is a non-empty folder: the rename fails, the .part is removed
  // and the folder is untouched.
  std::filesystem::create_directories(dir / "taken.vtu/inside");
  msg = input_error_message([&] { write_vtu_surface_mesh(dir / "taken.vtu", ico); });
  expect_contains_all(msg, {"taken.vtu", "cannot write"});
  EXPECT_FALSE(std::filesystem::exists(dir / "taken.vtu.part"));
  EXPECT_TRUE(std::filesystem::is_directory(dir / "taken.vtu/inside"));
  // Overwriting an existing file replaces it whole.
  write_vtu_surface_mesh(dir / "a.vtu", make_icosphere(1));
  write_vtu_surface_mesh(dir / "a.vtu", ico);
  EXPECT_EQ(read_vtu_surface_mesh(dir / "a.vtu").F.rows(), 20);
}

TEST(VtkIo, ReaderRejectsMalformedFiles) {
  TempDir dir;
  write_vtu_surface_mesh(dir / "good.vtu", make_icosphere(0));
  std::ifstream in(dir / "good.vtu");
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto expect_error = [&](const std::string& name, const std::string& text,
                                std::initializer_list<std::string_view> parts,
                                bool as_tets = false) {
    SCOPED_TRACE(name);
    const auto path = write_bytes(dir / name, text);
    const std::string msg = input_error_message([&] {
      if (as_tets)
        read_vtu_tet_mesh(path);
      else
        read_vtu_surface_mesh(path);
    });
    expect_contains_all(msg, {name});
    expect_contains_all(msg, parts);
  };
  const auto replace = [&](std::string from, std::string to) {
    std::string s = good;
    const size_t p = s.find(from);
    EXPECT_NE(p, std::string::npos) << from;
    if (p != std::string::npos) s.replace(p, from.size(), to);
    return s;
  };
  expect_contains_all(input_error_message([&] { read_vtu(dir / "missing.vtu"); }),
                      {"missing.vtu", "no such file"});
  expect_error("text.vtu", "hello", {"not a VTK XML file"});
  expect_error("polydata.vtu", replace("UnstructuredGrid\" version", "PolyData\" version"),
               {"line 2", "expected 'UnstructuredGrid'"});
  expect_error("binary.vtu", replace("format=\"ascii\"", "format=\"binary\""),
               {"'binary'", "only format=\"ascii\""});
  expect_error("appended.vtu", replace("</UnstructuredGrid>", "</UnstructuredGrid><AppendedData>"),
               {"appended", "not supported"});
  expect_error("noconn.vtu", replace("Name=\"connectivity\"", "Name=\"conn\""), {"'connectivity'"});
  expect_error("count.vtu", replace("NumberOfPoints=\"12\"", "NumberOfPoints=\"13\""),
               {"NumberOfPoints=13"});
  expect_error("huge.vtu", replace("NumberOfPoints=\"12\"", "NumberOfPoints=\"1000000000000\""),
               {"exceeds"});
  expect_error(
      "nan.vtu",
      replace("Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">\n          ",
              "Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">\n          nan "),
      {"NaN"});
  expect_error("word.vtu",
               replace("Name=\"offsets\" format=\"ascii\">\n          3",
                       "Name=\"offsets\" format=\"ascii\">\n          three"),
               {"'offsets'", "'three'", "not an integer"});
  expect_error("offsets.vtu",
               replace("Name=\"offsets\" format=\"ascii\">\n          3\n          6",
                       "Name=\"offsets\" format=\"ascii\">\n          3\n          3"),
               {"cell 1", "offset 3"});
  expect_error("range.vtu",
               replace("Name=\"connectivity\" format=\"ascii\">\n          0",
                       "Name=\"connectivity\" format=\"ascii\">\n          12"),
               {"cell 0", "index 12", "out of range"});
  expect_error("type.vtu",
               replace("Name=\"types\" format=\"ascii\">\n          5",
                       "Name=\"types\" format=\"ascii\">\n          7"),
               {"cell 0", "VTK type 7", "VTK_TRIANGLE"});
  expect_error("tri_as_tet.vtu", good, {"cell 0", "VTK_TETRA"}, true);
  expect_error("truncated.vtu", good.substr(0, good.size() / 2), {});
  // An inverted tet is refused with its index.
  TetMesh t = make_box_tet_mesh({});
  std::swap(t.T(4, 1), t.T(4, 2));
  write_vtu_tet_mesh(dir / "inverted.vtu", t);
  expect_contains_all(input_error_message([&] { read_vtu_tet_mesh(dir / "inverted.vtu"); }),
                      {"inverted.vtu", "tet 4", "inverted"});
  // A sphere set needs its radius array.
  expect_contains_all(input_error_message([&] { read_vtu_sphere_set(dir / "good.vtu"); }),
                      {"good.vtu", "VTK_VERTEX"});
  // Every prefix of a valid file (short of the final newline) is refused cleanly.
  for (size_t len = 0; len + 1 < good.size(); ++len)
    EXPECT_THROW(parse_vtu(std::string_view(good).substr(0, len), "x.vtu"), InputError) << len;
}

}  // namespace
}  // namespace icd
