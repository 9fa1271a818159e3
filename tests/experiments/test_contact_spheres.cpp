#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <icd/collision/sphere_tree.hpp>
#include "experiments/runner/run.hpp"
#include "experiments/runner/run.hpp"
#include <icd/mesh/io/vtu_reader.hpp>
#include "tests/experiments/head_on_scene.hpp"

namespace icd::runner {
namespace {

namespace fs = std::filesystem;

const PointDataArray& array_named(const VtuData& d, const std::string& name) {
  for (const PointDataArray& a : d.point_data)
    if (a.name == name) return a;
  throw std::runtime_error("no point array " + name);
}

// Index of the node of `tree` whose sphere is (c, r) to the last bits; -1: none.
int find_node(const collision::SphereTree& tree, const Eigen::Vector3d& c, double r) {
  for (int i = 0; i < tree.num_nodes(); ++i) {
    const collision::Sphere& s = tree.spheres[i];
    if ((Eigen::Vector3d(s.x, s.y, s.z) - c).norm() <= 1e-12 && std::abs(s.r - r) <= 1e-12)
      return i;
  }
  return -1;
}

// The contact spheres the runner writes (VTU output, fig9) for one side of a
// pair are the spheres of that side's tree in the query's lists, in list
// order, so row k of side 0 and row k of side 1 are the two spheres of one
// pair. Checked by a brute-force search of each written sphere in the two
// trees (the objects are apart, so a sphere is found in its own side's tree
// only), and geometrically: a colliding leaf pair must overlap and be made of
// leaves. (Untested pairs need not overlap: when a budget stops a query in
// the middle of a node's children, the children pairs not yet tested are
// reported untested.) Run on
// the head-on scene until a query reached leaves (complete query) or, with a
// small test budget, was interrupted with pairs left untested.
void expect_written_pairs_overlap(const std::string& collision, bool expect_untested) {
  World world = make_world(head_on_scene(collision), "", "");
  // One folder per test and process: CTest runs these tests side by side.
  const fs::path dir =
      fs::path(::testing::TempDir()) /
      ("icd_contact_spheres_" +
       std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
       std::to_string(::getpid()));
  fs::create_directories(dir);
  struct RemoveOnExit {
    fs::path dir;
    ~RemoveOnExit() { fs::remove_all(dir); }
  } cleanup{dir};
  for (int f = 0; f < 30; ++f) {
    world.step();
    const collision::CollisionResult& r = world.results()[0];
    if (expect_untested ? r.untested.empty() : r.colliding.empty()) continue;
    VtuData side[2];
    for (int s = 0; s < 2; ++s) {
      const fs::path path = dir / ("side" + std::to_string(s) + ".vtu");
      write_contact_spheres(world, 0, s, path);
      side[s] = read_vtu(path);
    }
    const size_t n = r.colliding.size() + r.untested.size();
    ASSERT_EQ(static_cast<size_t>(side[0].points.rows()), n);
    ASSERT_EQ(static_cast<size_t>(side[1].points.rows()), n);
    const collision::SphereTree* trees[2] = {&world.objects()[0].asset.spheres,
                                             &world.objects()[1].asset.spheres};
    const SphereSet set0 = read_vtu_sphere_set(dir / "side0.vtu");
    const SphereSet set1 = read_vtu_sphere_set(dir / "side1.vtu");
    const PointDataArray& flag0 = array_named(side[0], "colliding_leaf");
    const PointDataArray& flag1 = array_named(side[1], "colliding_leaf");
    const PointDataArray& level0 = array_named(side[0], "level");
    size_t leaves = 0;
    for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(n); ++k) {
      const SphereSet* sets[2] = {&set0, &set1};
      int node[2];
      for (int s = 0; s < 2; ++s) {
        const Eigen::Vector3d c = sets[s]->centers.row(k).transpose();
        node[s] = find_node(*trees[s], c, sets[s]->radii[k]);
        EXPECT_GE(node[s], 0) << "row " << k << " of side " << s << " is no sphere of its tree";
        EXPECT_EQ(find_node(*trees[1 - s], c, sets[s]->radii[k]), -1)
            << "row " << k << " of side " << s;
      }
      EXPECT_EQ(flag0.values(k, 0), flag1.values(k, 0)) << "row " << k;
      if (node[0] >= 0) {
        EXPECT_EQ(level0.values(k, 0), trees[0]->level[node[0]]) << "row " << k;
      }
      if (flag0.values(k, 0) == 1.0) {
        ++leaves;
        const double gap =
            (set0.centers.row(k) - set1.centers.row(k)).norm() - set0.radii[k] - set1.radii[k];
        EXPECT_LE(gap, 1e-12) << "row " << k << ": a colliding leaf pair that does not overlap";
        for (int s = 0; s < 2; ++s)
          if (node[s] >= 0) {
            EXPECT_TRUE(trees[s]->is_leaf(node[s])) << "row " << k << " of side " << s;
          }
      }
    }
    EXPECT_EQ(leaves, r.colliding.size());
    return;
  }
  FAIL() << "no query with " << (expect_untested ? "untested" : "colliding")
         << " pairs in 30 frames";
}

TEST(ContactSpheres, CompleteQueryWritesOverlappingLeafPairs) {
  expect_written_pairs_overlap(R"("budget_tests": 1000000)", false);
}

TEST(ContactSpheres, InterruptedQueryWritesItsUntestedPairsToo) {
  expect_written_pairs_overlap(R"("budget_tests": 60)", true);
}

}  // namespace
}  // namespace icd::runner
