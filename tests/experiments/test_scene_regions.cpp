// Region selectors (fixed nodes, loads) and keyframed motion in scene files.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>

#include "experiments/runner/scene.hpp"
#include <icd/mesh/core/error.hpp>

namespace icd::runner {
namespace {

Scene parse(const std::string& objects) {
  return parse_scene(parse_json("{\"objects\": [" + objects + "]}", "s.json"), "s.json", ".");
}

template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

MatX3d cloud(int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  MatX3d x(n, 3);
  for (int i = 0; i < n; ++i) x.row(i) << u(rng), u(rng), u(rng);
  return x;
}

// Brute force, written independently of RegionSelector::contains: each
// coordinate against the box, the plane's signed distance from the
// unnormalised normal, squared distances for "near".
std::set<int> brute(const MatX3d& x, double x0, double x1, double y0, double y1, double z0,
                    double z1) {
  std::set<int> s;
  for (int i = 0; i < x.rows(); ++i)
    if (x(i, 0) >= x0 && x(i, 0) <= x1 && x(i, 1) >= y0 && x(i, 1) <= y1 && x(i, 2) >= z0 &&
        x(i, 2) <= z1)
      s.insert(i);
  return s;
}

std::set<int> as_set(const std::vector<int>& v) { return {v.begin(), v.end()}; }

TEST(SceneRegions, SelectorsMatchBruteForce) {
  const MatX3d x = cloud(2000);
  const Scene s = parse(R"({"name": "a", "primitive": {"type": "sphere"},
      "fixed": {"box": {"min": [-0.5, -1, 0.2], "max": [0.3, 0.4, 1]}}},
    {"name": "b", "primitive": {"type": "sphere"},
      "fixed": {"plane": {"point": [0.1, 0, 0], "normal": [2, 1, 0], "tolerance": 0.05}}},
    {"name": "c", "primitive": {"type": "sphere"},
      "fixed": [{"near": {"point": [0.2, -0.3, 0.1], "distance": 0.4}},
                {"box": {"min": [0.5, 0.5, 0.5], "max": [1, 1, 1]}}]})");
  EXPECT_EQ(as_set(select_nodes(s.objects[0].fixed_regions, x)), brute(x, -0.5, 0.3, -1, 0.4, 0.2, 1));
  std::set<int> plane, near;
  for (int i = 0; i < x.rows(); ++i) {
    if ((2 * (x(i, 0) - 0.1) + x(i, 1)) / std::sqrt(5.0) <= 0.05) plane.insert(i);
    const double dx = x(i, 0) - 0.2, dy = x(i, 1) + 0.3, dz = x(i, 2) - 0.1;
    if (dx * dx + dy * dy + dz * dz <= 0.16) near.insert(i);
  }
  EXPECT_EQ(as_set(select_nodes(s.objects[1].fixed_regions, x)), plane);
  std::set<int> both = near;
  for (int i : brute(x, 0.5, 1, 0.5, 1, 0.5, 1)) both.insert(i);
  EXPECT_EQ(as_set(select_nodes(s.objects[2].fixed_regions, x)), both);
  EXPECT_GT(plane.size(), 100u);  // the cloud is not trivially split
  EXPECT_LT(plane.size(), 1900u);
}

TEST(SceneRegions, FixedRegionsAndLoadsResolveOnTheCoarseNodes) {
  const MatX3d x = cloud(500);
  const Scene s = parse(R"({"name": "a", "primitive": {"type": "sphere"}, "fixed_nodes": [3],
      "fixed": {"box": {"min": [-1, -1, -1], "max": [1, 1, -0.8]}},
      "loads": [{"region": {"box": {"min": [-1, -1, 0.8], "max": [1, 1, 1]}}, "total_force": [0, 0, -6]},
                {"region": {"near": {"point": [0, 0, 0], "distance": 0.3}}, "force_per_node": [1, 0, 0]}]})");
  coupling::ObjectSetup setup = s.objects[0];
  const MatX3d f = apply_regions(s.objects[0], setup, x);
  std::set<int> expect = brute(x, -1, 1, -1, 1, -1, -0.8);
  expect.insert(3);
  EXPECT_EQ(as_set(setup.fixed_nodes), expect);
  EXPECT_EQ(setup.fixed_nodes.size(), expect.size());  // no duplicates
  const std::set<int> top = brute(x, -1, 1, -1, 1, 0.8, 1);
  int centre = 0;
  for (int i = 0; i < x.rows(); ++i) {
    const bool in_top = top.count(i) > 0, in_centre = x.row(i).norm() <= 0.3;
    centre += in_centre;
    EXPECT_NEAR(f(i, 2), in_top ? -6.0 / static_cast<double>(top.size()) : 0.0, 1e-12) << i;
    EXPECT_EQ(f(i, 0), in_centre ? 1.0 : 0.0) << i;
  }
  EXPECT_NEAR(f.col(2).sum(), -6.0, 1e-12);  // the total is the total
  EXPECT_DOUBLE_EQ(f.col(0).sum(), centre);
}

TEST(SceneRegions, ARegionMatchingNoNodeIsAnErrorNamingTheField) {
  const Scene s = parse(R"({"name": "a", "primitive": {"type": "sphere"},
      "fixed": [{"box": {"min": [-1, -1, -1], "max": [1, 1, 1]}},
                {"near": {"point": [5, 5, 5], "distance": 0.1}}]})");
  coupling::ObjectSetup setup = s.objects[0];
  const std::string msg = input_error([&] { apply_regions(s.objects[0], setup, cloud(50)); });
  EXPECT_NE(msg.find("s.json: objects[0].fixed[1].near: selects no coarse node"), std::string::npos)
      << msg;
}

TEST(SceneRegions, BadSelectorsAreRefusedNamingTheField) {
  const auto err = [](const std::string& extra) {
    return input_error([&] { parse(R"({"name": "a", "primitive": {"type": "sphere"}, )" + extra + "}"); });
  };
  EXPECT_NE(err(R"("fixed": {"box": {"min": [0, 0, 0]}})").find("objects[0].fixed.box: needs \"min\" and \"max\""),
            std::string::npos);
  EXPECT_NE(err(R"("fixed": {"box": {"min": [0, 0, 0], "max": [1, -1, 1]}})").find("fixed.box.max: must be >= min"),
            std::string::npos);
  EXPECT_NE(err(R"("fixed": {"plane": {"point": [0, 0, 0], "normal": [0, 0, 0]}})").find("fixed.plane.normal: must be a non-zero"),
            std::string::npos);
  EXPECT_NE(err(R"("fixed": {"sphere": {}})").find("objects[0].fixed: needs exactly one of"), std::string::npos);
  EXPECT_NE(err(R"("fixed": [])").find("objects[0].fixed: must not be an empty array"), std::string::npos);
  EXPECT_NE(err(R"("fixed": {"near": {"point": [0, 0, 0], "distance": -1}})").find("fixed.near.distance: must be in [0"),
            std::string::npos);
  EXPECT_NE(err(R"("loads": [{"region": {"near": {"point": [0, 0, 0], "distance": 1}}}])").find("objects[0].loads[0]: needs exactly one of"),
            std::string::npos);
  EXPECT_NE(err(R"("kind": "rigid", "loads": [])").find("only a deformable object takes loads"), std::string::npos);
  EXPECT_NE(err(R"("motion": {"keyframes": [{"t": 0, "position": [0, 0, 0]}]})").find("objects[0].motion: only a rigid"),
            std::string::npos);
  EXPECT_NE(err(R"("kind": "rigid", "motion": {"keyframes": [{"t": 1, "position": [0, 0, 0]}, {"t": 1, "position": [0, 0, 0]}]})")
                .find("motion.keyframes[1].t: must be later than the previous key's (1), got 1"),
            std::string::npos);
  EXPECT_NE(err(R"("kind": "rigid", "motion": {"keyframes": [{"t": 0, "position": [0, 0, 0], "rotation": {"axis": [0, 0, 1]}}]})")
                .find("keyframes[0].rotation: needs"),
            std::string::npos);
  EXPECT_NE(err(R"("kind": "rigid", "motion": {"keyframes": [{"t": 0, "posiiton": [0, 0, 0]}]})").find("keyframes[0]: needs \"t\" and \"position\""),
            std::string::npos);
  EXPECT_NE(err(R"("kind": "rigid", "motion": {"keyframes": [], "interpolation": "linear"})").find("motion.keyframes: must be a non-empty"),
            std::string::npos);
  EXPECT_NE(err(R"("kind": "rigid", "motion": {"keyframes": [{"t": 0, "position": [0, 0, 0]}], "interpolation": "cubic"})").find("motion.interpolation: must be one of"),
            std::string::npos);
}

// The scene's keyframes become a motion of the rest nodes about the object's
// "position" point: the pivot lands on the interpolated position and the
// nodes turn by the slerped rotation.
TEST(SceneRegions, KeyframesDriveTheObjectAboutItsPosition) {
  const Scene s = parse(R"({"name": "probe", "kind": "rigid", "primitive": {"type": "sphere"},
      "position": [1, 2, 3],
      "motion": {"keyframes": [
        {"t": 0, "position": [1, 2, 3]},
        {"t": 2, "position": [1, 2, 1], "rotation": {"axis": [0, 0, 1], "angle_deg": 90}},
        {"t": 3, "position": [0, 0, 0], "rotation": {"quaternion": [0, 0, 0, 1]}}]}})");
  coupling::ObjectSetup setup = s.objects[0];
  apply_regions(s.objects[0], setup, cloud(10));
  ASSERT_TRUE(static_cast<bool>(setup.motion));
  const Eigen::Vector3d c(1, 2, 3), x = c + Eigen::Vector3d(0.5, 0, 0);
  // t = 1: halfway down, turned 45 degrees about z.
  const double a = M_PI / 4;
  const Eigen::Vector3d expect1 = Eigen::Vector3d(1, 2, 2) + 0.5 * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
  EXPECT_LT((setup.motion(1.0).apply(x) - expect1).norm(), 1e-12);
  EXPECT_LT((setup.motion(-1.0).apply(x) - x).norm(), 1e-12);  // before the first key: hold it
  EXPECT_LT((setup.motion(0.0).apply(x) - x).norm(), 1e-12);
  // After the last key: at the origin, turned 180 degrees about z.
  EXPECT_LT((setup.motion(10.0).apply(x) - Eigen::Vector3d(-0.5, 0, 0)).norm(), 1e-12);
}

TEST(SceneRegions, PlaneObstacleShorthand) {
  const Scene s = parse_scene(
      parse_json(R"({"objects": [{"name": "a", "primitive": {"type": "sphere"}}],
                     "obstacles": [{"plane": {"point": [0, 0, -1], "normal": [0, 3, 4]}},
                                   {"type": "box", "center": [0, 0, 0], "extent": [1, 1, 1]}]})",
                 "s.json"),
      "s.json", ".");
  ASSERT_EQ(s.world.obstacles.size(), 2u);
  EXPECT_EQ(s.world.obstacles[0].type, coupling::Obstacle::Type::Plane);
  EXPECT_LT((s.world.obstacles[0].normal - Eigen::Vector3d(0, 0.6, 0.8)).norm(), 1e-15);
  EXPECT_EQ(s.world.obstacles[0].point, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(s.world.obstacles[1].type, coupling::Obstacle::Type::Box);
  const std::string msg = input_error([] {
    parse_scene(parse_json(R"({"objects": [{"name": "a", "primitive": {"type": "sphere"}}],
                              "obstacles": [{"plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}, "type": "box"}]})",
                           "s.json"),
                "s.json", ".");
  });
  EXPECT_NE(msg.find("obstacles[0].type: unknown field"), std::string::npos) << msg;
}

}  // namespace
}  // namespace icd::runner
