#include <icd/fem/reorder.hpp>

#include <algorithm>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include <icd/fem/forces.hpp>
#include "fem_test_utils.hpp"

namespace icd::fem {
namespace {

// A structured bar with nodes and elements shuffled (generator order lost).
TetMesh shuffled_bar(unsigned seed) {
  const TetMesh m = test::box(20, 3, 3);
  std::vector<int> perm(m.V.rows()), eperm(m.T.rows());
  std::iota(perm.begin(), perm.end(), 0);
  std::iota(eperm.begin(), eperm.end(), 0);
  std::mt19937 gen(seed);
  std::shuffle(perm.begin(), perm.end(), gen);
  std::shuffle(eperm.begin(), eperm.end(), gen);
  TetMesh s;
  s.V.resize(m.V.rows(), 3);
  for (int i = 0; i < m.V.rows(); ++i) s.V.row(perm[i]) = m.V.row(i);
  s.T.resize(m.T.rows(), 4);
  for (int e = 0; e < m.T.rows(); ++e)
    for (int a = 0; a < 4; ++a) s.T(eperm[e], a) = perm[m.T(e, a)];
  return s;
}

TEST(Reorder, IsAPermutationThatKeepsGeometryOrientationAndForces) {
  const TetMesh s = shuffled_bar(3);
  const ReorderedMesh r = reorder_for_locality(s.V, s.T);
  std::vector<int> sorted = r.new_to_old_node;
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < static_cast<int>(sorted.size()); ++i) ASSERT_EQ(sorted[i], i);
  for (int i = 0; i < s.V.rows(); ++i) {
    EXPECT_EQ(r.V.row(i), s.V.row(r.new_to_old_node[i]));
    EXPECT_EQ(r.old_to_new_node[r.new_to_old_node[i]], i);
  }
  // Same volumes (orientation kept) element by element.
  const Eigen::VectorXd v_old = signed_tet_volumes(s.V, s.T), v_new = signed_tet_volumes(r.V, r.T);
  for (int e = 0; e < r.T.rows(); ++e) EXPECT_EQ(v_new[e], v_old[r.new_to_old_element[e]]);
  // Forces of a deformed state agree after mapping back (summation order differs: 1e-12).
  const MatX3d d = 0.002 * test::random_field(static_cast<int>(s.V.rows()), 5);
  ElasticForces f_old(make_tet_mesh_data(s.V, s.T), test::material(MaterialModel::StVK));
  ElasticForces f_new(make_tet_mesh_data(r.V, r.T), test::material(MaterialModel::StVK));
  MatX3d x_new(s.V.rows(), 3), fo(s.V.rows(), 3), fn(s.V.rows(), 3);
  for (int i = 0; i < s.V.rows(); ++i)
    x_new.row(i) = s.V.row(r.new_to_old_node[i]) + d.row(r.new_to_old_node[i]);
  f_old.compute(s.V + d, fo);
  f_new.compute(x_new, fn);
  for (int i = 0; i < s.V.rows(); ++i)
    EXPECT_LT((fn.row(i) - fo.row(r.new_to_old_node[i])).norm(), 1e-12 * fo.norm());
}

TEST(Reorder, ReducesTheBandwidthOfAShuffledMeshToNearTheStructuredOne) {
  const TetMesh m = test::box(20, 3, 3);
  const TetMesh s = shuffled_bar(4);
  const ReorderedMesh r = reorder_for_locality(s.V, s.T);
  // Structured numbering: bandwidth (nx+1)(ny+1) + (nx+1) + 1 = 21*4 + 22 = 106.
  EXPECT_EQ(node_bandwidth(m.T), 106);
  EXPECT_GT(node_bandwidth(s.T), 300);  // of 336 nodes
  // RCM along the bar's long axis: a cross-section has 16 nodes, so a band of
  // a few cross-sections: well below the structured x-fastest numbering.
  EXPECT_LT(node_bandwidth(r.T), 60);
  // Consecutive elements share nodes: the smallest index is non-decreasing.
  for (int e = 0; e + 1 < r.T.rows(); ++e)
    EXPECT_LE(r.T.row(e).minCoeff(), r.T.row(e + 1).minCoeff());
}

}  // namespace
}  // namespace icd::fem
