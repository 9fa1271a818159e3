// The real meshes of the paper's scenes (fetched by scripts/fetch_meshes.sh):
// counts stated by the issue, topology, and an exact OFF write/read round trip.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include <icd/config.hpp>
#include "io_test_util.hpp"
#include <icd/mesh/core/mesh_stats.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/surface_writer.hpp>

namespace icd {
namespace {

std::filesystem::path data_file(const char* name) {
  const char* env = std::getenv("ICD_DATA_DIR");
  return std::filesystem::path(env && *env ? env : ICD_DATA_DIR) / name;
}

TEST(RealMeshes, Bunny) {
  const auto path = data_file("bunny00.off");
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " missing (run scripts/fetch_meshes.sh)";
  ReadReport report;
  const SurfaceMesh m = read_surface_mesh(path, &report);
  EXPECT_EQ(m.V.rows(), 37706);
  EXPECT_EQ(m.F.rows(), 75408);
  EXPECT_EQ(report.polygons_triangulated, 0);
  const SurfaceStats s = compute_surface_stats(m);
  EXPECT_EQ(s.boundary_edges, 0);  // closed
  EXPECT_EQ(s.nonmanifold_edges, 0);
  EXPECT_EQ(s.euler_characteristic, 2);
  EXPECT_GT(s.volume, 0.0);  // outward-oriented
  // Exact round trip through our OFF writer.
  test::TempDir dir;
  write_off(dir / "bunny.off", m);
  const SurfaceMesh back = read_surface_mesh(dir / "bunny.off");
  EXPECT_TRUE(back.V == m.V);
  EXPECT_TRUE(back.F == m.F);
}

TEST(RealMeshes, Dragon) {
  const auto path = data_file("ChineseDragon-10kv.off");
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " missing (run scripts/fetch_meshes.sh)";
  const SurfaceMesh m = read_surface_mesh(path);
  EXPECT_EQ(m.V.rows(), 10000);
  EXPECT_EQ(m.F.rows(), 19994);
  const SurfaceStats s = compute_surface_stats(m);
  EXPECT_EQ(s.boundary_edges, 6);  // two small holes
  EXPECT_EQ(s.nonmanifold_edges, 0);
}

}  // namespace
}  // namespace icd
