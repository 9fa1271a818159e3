// The evaluate_sph program on a tree written as the reference toolkit writes
// it (trailing options and evaluation after the nodes): its rows for our
// probe frame and the toolkit's against the closed-form distance to a cube,
// and its refusals of bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include <icd/collision/sph_io.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/surface_writer.hpp>
#include <icd/mesh/spheres/evaluation.hpp>
#include "mesh/program_run.hpp"

namespace {

namespace fs = std::filesystem;

#ifdef ICD_EVALUATE_SPH
using icd::test::ProgramRun;

ProgramRun run_program(const std::string& args, const fs::path& dir) {
  return icd::test::run_program(ICD_EVALUATE_SPH, args, dir);
}

/// The table row (whitespace-separated fields) of `method` at `level`.
std::vector<std::string> row(const std::string& output, const std::string& method, int level) {
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::vector<std::string> f;
    for (std::string x; fields >> x;) f.push_back(x);
    if (f.size() >= 10 && f[1] == method && f[2] == std::to_string(level)) return f;
  }
  return {};
}

/// The cube [-1, 1]^3 turned by `turn`, off the axes (along an axis, a
/// direction both probe frames contain, they would see the same distance).
const Eigen::Matrix3d kTurn =
    Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 3).normalized()).matrix();

/// Largest distance from the probes c + r d (d: rows of dirs) to the turned
/// cube, in normalized units (its bounding box's longest side is 2000).
double turned_cube_error(const Eigen::Vector3d& c, double r, const icd::MatX3d& dirs, double side) {
  double e = 0;
  for (Eigen::Index k = 0; k < dirs.rows(); ++k) {
    const Eigen::Vector3d p = kTurn.transpose() * (c + r * dirs.row(k).transpose());
    e = std::max(e, (p.cwiseAbs().array() - 1.0).max(0.0).matrix().norm());
  }
  return e * 2000.0 / side;
}
#endif

TEST(EvaluateSphProgram, EvaluatesAToolkitFileInBothFramesAndRefusesBadInput) {
#ifndef ICD_EVALUATE_SPH
  GTEST_SKIP() << "evaluate_sph is not built";
#else
  const fs::path dir =
      fs::temp_directory_path() / ("icd_evaluate_sph_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  // The turned cube moved to `shift`, its bounding-box centre.
  const Eigen::Vector3d shift(5, -3, 2);
  icd::SurfaceMesh cube = icd::make_box_surface({-1, -1, -1}, {1, 1, 1});
  cube.V = cube.V * kTurn.transpose();
  cube.V.rowwise() += shift.transpose();
  const double side = (cube.V.colwise().maxCoeff() - cube.V.colwise().minCoeff()).maxCoeff();
  icd::write_off(dir / "cube.off", cube);
  const Eigen::Vector3d child(0.3, 0.1, -0.2);  // relative to the cube's centre
  const double child_r = 1.05;
  // The tree in the mesh's coordinates (cube.sph), and centred on the
  // bounding-box centre with the options and evaluation appended, as
  // makeTreeMedial writes it (cube-medial.sph).
  const std::vector<std::pair<std::string, Eigen::Vector3d> > files = {
      {"cube.sph", shift}, {"cube-medial.sph", Eigen::Vector3d::Zero()}};
  for (const auto& [file, origin] : files) {
    const Eigen::Vector3d c = origin + child;
    std::ofstream sph(dir / file);
    sph << std::setprecision(17) << "2 2\n"
        << origin.x() << " " << origin.y() << " " << origin.z() << " 1.8 1\n"
        << c.x() << " " << c.y() << " " << c.z() << " " << child_r << " 1\n"
        << "0 0 0 -1 0\n\n\nOptions :\n\ttesterLevels\t: 2\n\tbranch\t: 2\n\n\n"
        << "Level 0 : 1 spheres\n";
  }
  const std::string common = " --coverage-spacing 40 --shell-samples 0 --rotations 2 --dense 0";
  const std::string mesh_arg = (dir / "cube.off").string() + " ";
  const ProgramRun ok = run_program(mesh_arg + (dir / "cube.sph").string() + common, dir);
  ASSERT_EQ(ok.status, 0) << ok.output;
  const icd::MatX3d ours = icd::mesh::probe_directions(1);
  const icd::MatX3d toolkit = ours * icd::mesh::toolkit_probe_frame().transpose();
  const double expected_ours = turned_cube_error(child, child_r, ours, side);
  const double expected_toolkit = turned_cube_error(child, child_r, toolkit, side);
  ASSERT_GT(std::abs(expected_ours - expected_toolkit), 1.0);  // the frames differ here
  const auto a = row(ok.output, "ours", 1), b = row(ok.output, "toolkit", 1);
  ASSERT_FALSE(a.empty()) << ok.output;
  ASSERT_FALSE(b.empty()) << ok.output;
  EXPECT_EQ(a[3], "1");                                // spheres
  EXPECT_NEAR(std::stod(a[4]), expected_ours, 0.051);  // worst42, one decimal
  EXPECT_NEAR(std::stod(b[4]), expected_toolkit, 0.051);
  EXPECT_FALSE(row(ok.output, "ours", 0).empty());

  // The centred file with --centred 1: the same rows; without it, elsewhere.
  const ProgramRun centred =
      run_program(mesh_arg + (dir / "cube-medial.sph").string() + common + " --centred 1", dir);
  ASSERT_EQ(centred.status, 0) << centred.output;
  for (const char* method : {"ours", "toolkit"}) {
    for (int level : {0, 1}) {
      const auto expected = row(ok.output, method, level), got = row(centred.output, method, level);
      ASSERT_EQ(got.size(), expected.size()) << centred.output;
      for (size_t k = 4; k < got.size(); ++k) EXPECT_EQ(got[k], expected[k]) << method << " " << k;
    }
  }
  const ProgramRun uncentred =
      run_program(mesh_arg + (dir / "cube-medial.sph").string() + common, dir);
  ASSERT_EQ(uncentred.status, 0) << uncentred.output;
  EXPECT_NE(row(uncentred.output, "ours", 1).at(4), a[4]);

  // --cover-leaves: the one leaf gets every uncovered sample, so its radius
  // becomes the distance to the farthest point of the cube, a corner (the
  // corners are samples); the grown tree is evaluated covering.
  const ProgramRun grown = run_program(mesh_arg + (dir / "cube.sph").string() + common +
                                           " --cover-leaves " + (dir / "grown.sph").string(),
                                       dir);
  ASSERT_EQ(grown.status, 0) << grown.output;
  double farthest = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d v(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
    farthest = std::max(farthest, (kTurn * v - child).norm());
  }
  const icd::collision::SphereTree grown_tree =
      icd::collision::read_sph((dir / "grown.sph").string());
  ASSERT_EQ(grown_tree.num_nodes(), 2);
  EXPECT_NEAR(grown_tree.spheres[1].r, farthest, 1e-8);
  EXPECT_EQ(grown_tree.spheres[0].r, 1.8);  // upper levels unchanged
  EXPECT_EQ(row(grown.output, "ours", 1).at(10), "0.00000%");
  EXPECT_NE(a[10], "0.00000%");  // the leaf did not cover before
  // --cover-only-as the tree itself: the leaf shrinks to the farthest sample
  // it covers, within one sample spacing (40 of 2000 units) of its radius.
  const ProgramRun shrunk =
      run_program(mesh_arg + (dir / "cube.sph").string() + common + " --cover-only-as " +
                      (dir / "cube.sph").string() + " --shrunk " + (dir / "shrunk.sph").string(),
                  dir);
  ASSERT_EQ(shrunk.status, 0) << shrunk.output;
  const icd::collision::SphereTree shrunk_tree =
      icd::collision::read_sph((dir / "shrunk.sph").string());
  EXPECT_LE(shrunk_tree.spheres[1].r, child_r * (1 + 1e-8));
  EXPECT_GE(shrunk_tree.spheres[1].r, child_r - 40.0 * side / 2000.0);
  EXPECT_EQ(row(shrunk.output, "ours", 1).at(10), a[10]);  // the same samples uncovered

  // A NaN radius: status 1, the file and the node named.
  {
    std::ofstream sph(dir / "bad.sph");
    sph << "1 2\n0 0 0 nan 1\n";
  }
  const ProgramRun bad =
      run_program((dir / "cube.off").string() + " " + (dir / "bad.sph").string() + common, dir);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.output.find("bad.sph: line 2: node 0 has a non-finite value"), std::string::npos)
      << bad.output;
  // A missing argument: status 2 and the usage.
  const ProgramRun usage = run_program((dir / "cube.off").string(), dir);
  EXPECT_EQ(usage.status, 2);
  EXPECT_NE(usage.output.find("TREE"), std::string::npos) << usage.output;
  // Bad option values are command-line errors (status 2, the option named,
  // nothing written), before any file is read.
  const std::string trees = mesh_arg + (dir / "cube.sph").string() + common;
  const std::pair<std::string, std::string> bad_options[] = {
      {" --sample-spacing 0 --sample-table " + (dir / "samples.csv").string(),
       "evaluate_sph: --sample-spacing must be > 0, got '0' (see --help)"},
      {" --coverage-spacing -1", "evaluate_sph: --coverage-spacing must be > 0, got '-1' (see --help)"},
      {" --cover-only-as " + (dir / "cube.sph").string(),
       "evaluate_sph: --cover-only-as and --shrunk go together (see --help)"}};
  for (const auto& [options, message] : bad_options) {
    const ProgramRun refused = run_program(trees + options, dir);
    EXPECT_EQ(refused.status, 2) << options << ": " << refused.output;
    EXPECT_NE(refused.output.find(message), std::string::npos) << refused.output;
  }
  EXPECT_FALSE(fs::exists(dir / "samples.csv"));
  fs::remove_all(dir);
#endif
}

}  // namespace
