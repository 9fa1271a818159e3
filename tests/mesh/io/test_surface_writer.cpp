// OFF/OBJ writers: exact round trips through the readers (including extreme
// doubles), and validation without partial output.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "io_test_util.hpp"
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/surface_writer.hpp>

namespace icd {
namespace {

using test::TempDir;

SurfaceMesh awkward_values_mesh() {
  SurfaceMesh m = make_torus(1.0, 0.4, 7, 5);
  std::mt19937 rng(0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Eigen::Index i = 0; i < m.V.size(); ++i) m.V.data()[i] += 1e-9 * u(rng);
  m.V(0, 0) = std::numeric_limits<double>::max();
  m.V(0, 1) = std::numeric_limits<double>::denorm_min();
  m.V(0, 2) = -0.0;
  m.V(1, 0) = -std::numeric_limits<double>::min();
  m.V(1, 1) = 1.0 / 3.0;
  m.V(1, 2) = 123456789012345678.0;
  return m;
}

TEST(SurfaceWriter, OffAndObjRoundTripBitExactly) {
  TempDir dir;
  const SurfaceMesh m = awkward_values_mesh();
  for (const char* name : {"m.off", "m.obj", "M.OBJ"}) {
    write_surface_mesh(dir / name, m);
    const SurfaceMesh back = read_surface_mesh(dir / name);
    ASSERT_EQ(back.V.rows(), m.V.rows()) << name;
    for (Eigen::Index i = 0; i < m.V.size(); ++i)  // bit patterns, so -0.0 is checked too
      EXPECT_EQ(std::signbit(back.V.data()[i]), std::signbit(m.V.data()[i])) << name;
    EXPECT_TRUE(back.V == m.V) << name;
    EXPECT_TRUE(back.F == m.F) << name;
    EXPECT_FALSE(std::filesystem::exists(dir / (std::string(name) + ".part")));
  }
}

TEST(SurfaceWriter, RejectsBadMeshesAndExtensions) {
  TempDir dir;
  SurfaceMesh m = make_box_surface({0, 0, 0}, {1, 1, 1});
  EXPECT_THROW(write_surface_mesh(dir / "m.stl", m), ParameterError);
  SurfaceMesh bad = m;
  bad.F(2, 0) = -1;
  EXPECT_THROW(write_off(dir / "m.off", bad), ParameterError);
  bad = m;
  bad.V(3, 1) = std::nan("");
  EXPECT_THROW(write_obj(dir / "m.obj", bad), ParameterError);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace icd
