// The shipped scene experiments/scenes/probe_on_floor.json: a plane floor, a
// block held at its base by a region selector, a keyframed probe. Run for a
// few frames in the library and through icd-run: the probe touches the
// block, the block pushes back, nothing goes through the floor.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <icd/config.hpp>
#include <icd/coupling/link_evaluator.hpp>

#include "experiments/runner/child_process.hpp"
#include "experiments/runner/run.hpp"
#include "experiments/runner/scene.hpp"

namespace icd::runner {
namespace {

namespace fs = std::filesystem;

const fs::path kScene = fs::path(ICD_SOURCE_DIR) / "experiments" / "scenes" / "probe_on_floor.json";
constexpr double kFloorTolerance = 1e-3;  // m: the obstacle projection's stated tolerance

TEST(ProbeScene, ProbePressesTheBlockWhichStaysOnTheFloor) {
  const Scene scene = load_scene(kScene, {"frames=30", "output.vtu_every=0"});
  ASSERT_EQ(scene.objects.size(), 2u);
  ASSERT_EQ(scene.world.obstacles.size(), 1u);
  World world = make_world(scene, fs::path(::testing::TempDir()) / "icd_probe_cache", ".", {});
  const RuntimeObject& block = world.objects()[0];
  const RuntimeObject& probe = world.objects()[1];
  // The base selector held exactly the nodes at z = 0 (brute force).
  std::vector<int> base;
  for (int v = 0; v < block.rest.rows(); ++v)
    if (std::abs(block.rest(v, 2)) <= 1e-3) base.push_back(v);
  ASSERT_FALSE(base.empty());
  EXPECT_EQ(block.setup.fixed_nodes, base);
  const MatX3d base_rest = block.rest;
  coupling::LinkEvaluator links(block.asset.links);
  MatX3d dense(block.asset.links.num_links(), 3);
  double force = 0, lowest = 1;
  int first_contact = -1;
  for (int f = 0; f < scene.frames; ++f) {
    const coupling::FrameMetrics m = world.step();
    if (m.contact_force > 0 && first_contact < 0) first_contact = f;
    force = std::max(force, m.contact_force);
    links.apply(block.positions, dense);
    lowest = std::min(lowest, dense.col(2).minCoeff());
  }
  RecordProperty("max_contact_force_N", std::to_string(force));
  RecordProperty("first_contact_frame", first_contact);
  RecordProperty("lowest_block_vertex_mm", std::to_string(lowest * 1e3));
  EXPECT_GT(force, 0.5);
  // The probe's bottom (z = 0.26 at t = 0, moving down 0.16 m/s) reaches the
  // top (z = 0.2) at t = 0.375 s, frame 22; the leaf spheres, which stand out
  // of the block's faces, touch a few frames sooner.
  EXPECT_GE(first_contact, 12);
  EXPECT_LE(first_contact, 22);
  EXPECT_GT(lowest, -kFloorTolerance);
  // The top was pressed down; the base did not move.
  for (int v : base) EXPECT_EQ(block.positions.row(v), base_rest.row(v));
  EXPECT_LT(block.positions.col(2).maxCoeff(), 0.2 - 1e-3);
  // The probe is where its keyframes put it at t = 0.5 s: centre at z = 0.22.
  const Eigen::Vector3d c = probe.positions.colwise().mean();
  EXPECT_NEAR(c.z() - probe.rest.colwise().mean()(2), 0.22 - 0.30, 1e-9);
}

TEST(ProbeScene, RunsWithIcdRun) {
  const fs::path out = fs::path(::testing::TempDir()) / "icd_probe_run";
  fs::remove_all(out);
  const ChildResult r = run_child({ICD_RUN_EXE, kScene.string(), "--frames", "25", "--set",
                                   "output.vtu_every=0", "--out", out.string(), "--quiet"});
  ASSERT_TRUE(r.ok()) << r.describe({});
  std::ifstream csv(out / "frames.csv");
  std::string header, line;
  ASSERT_TRUE(std::getline(csv, header));
  std::vector<std::string> cols;
  std::stringstream hs(header);
  for (std::string c; std::getline(hs, c, ',');) cols.push_back(c);
  const auto col = [&](const std::string& name) {
    return static_cast<size_t>(std::find(cols.begin(), cols.end(), name) - cols.begin());
  };
  const size_t force_col = col("contact_force"), depth_col = col("obstacle_depth");
  ASSERT_LT(force_col, cols.size());
  ASSERT_LT(depth_col, cols.size());
  int rows = 0, contact = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> v;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) v.push_back(c);
    ASSERT_EQ(v.size(), cols.size()) << line;
    ++rows;
    contact += std::stod(v[force_col]) > 0;
    // Deepest a block vertex got inside the floor before its projection.
    EXPECT_LT(std::stod(v[depth_col]), kFloorTolerance) << line;
  }
  EXPECT_EQ(rows, 25);
  EXPECT_GT(contact, 0);
}

}  // namespace
}  // namespace icd::runner
