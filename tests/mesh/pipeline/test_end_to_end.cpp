// End-to-end preprocessing of a real mesh (the Chinese dragon: two holes and
// self-intersections in the raw data), with the fast octree sphere builder.
// Skipped when the mesh has not been fetched (scripts/fetch_meshes.sh).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cstdlib>
#include <filesystem>
#include <random>

#include <icd/collision/sphere_tree.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/coupling/link_evaluator.hpp>
#include <icd/config.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include "mesh/pipeline/pipeline_test_utils.hpp"
#include <icd/mesh/pipeline/preprocess.hpp>

namespace icd::mesh {
namespace {

std::filesystem::path data_dir() {
  const char* env = std::getenv("ICD_DATA_DIR");
  return env ? std::filesystem::path(env) : std::filesystem::path(ICD_DATA_DIR);
}

TEST(EndToEnd, DragonDefaultsWithOctreeSpheres) {
  const auto path = data_dir() / "ChineseDragon-10kv.off";
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " missing (run scripts/fetch_meshes.sh)";
  const SurfaceMesh raw = read_surface_mesh(path);
  PreprocessOptions o;
  o.sphere_builder = SphereBuilder::octree;
  const PreprocessResult r = preprocess(raw, o, {}, path.string());
  const coupling::AssetBundle& b = r.bundle;

  // Repair: the two holes are filled, the result is closed and outward.
  EXPECT_EQ(r.repair.holes_filled, 2);
  EXPECT_TRUE(test::closed_and_oriented(b.dense.F));
  EXPECT_GT(test::enclosed_volume(b.dense.V, b.dense.F), 0.0);

  // Coarse mesh: count near the target, valid and sliver-free.
  EXPECT_NEAR(b.coarse.T.rows() / 2000.0, 1.0, 0.3);
  EXPECT_GT(signed_tet_volumes(b.coarse.V, b.coarse.T).minCoeff(), 0.0);
  EXPECT_TRUE(test::closed_and_oriented(b.coarse.F));
  EXPECT_GT(r.quality.min_dihedral_deg, 5.0);
  // The coarse volume is close to the dense one (within 5%).
  EXPECT_NEAR(r.quality.total_volume / test::enclosed_volume(b.dense.V, b.dense.F), 1.0, 0.05);
  EXPECT_LT(r.hausdorff_dense_coarse, 0.05 * r.bbox_diagonal);

  // Links reproduce the dense mesh at rest and under a rigid motion.
  MatX3d out(b.dense.V.rows(), 3);
  coupling::apply(b.links, b.coarse.V, out);
  EXPECT_LT((out - b.dense.V).rowwise().norm().maxCoeff(), 1e-12 * r.bbox_diagonal);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -1, 0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(100, -50, 20);
  const MatX3d moved = (b.coarse.V * R.transpose()).rowwise() + t;
  coupling::apply(b.links, moved, out);
  const MatX3d expected = (b.dense.V * R.transpose()).rowwise() + t;
  EXPECT_LT((out - expected).rowwise().norm().maxCoeff(), 1e-12 * (r.bbox_diagonal + t.norm()));

  // The runtime's grouped evaluator equals Eqs. 1-10 written out
  // (apply_reference) on the real links: at rest and under random affine
  // maps with per-node noise (1 % of the diagonal), no frame degenerate.
  coupling::LinkEvaluator ev(b.links);
  MatX3d fast(b.dense.V.rows(), 3), ref(b.dense.V.rows(), 3);
  ASSERT_EQ(ev.apply(b.coarse.V, fast).degenerate_triples, 0);
  EXPECT_LT((fast - b.dense.V).rowwise().norm().maxCoeff(), 1e-12 * r.bbox_diagonal);
  std::mt19937 rng(9);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> stretch(0.5, 2.0);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::Matrix3d Rt =
        Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    const Eigen::Matrix3d S =
        Eigen::Vector3d(stretch(rng), stretch(rng), stretch(rng)).asDiagonal();
    MatX3d X(b.coarse.V.rows(), 3);
    for (int i = 0; i < X.rows(); ++i) {
      const Eigen::Vector3d noisy =
          b.coarse.V.row(i).transpose() +
          0.01 * r.bbox_diagonal * Eigen::Vector3d(g(rng), g(rng), g(rng));
      X.row(i) = (Rt * S * noisy).transpose();
    }
    EXPECT_EQ(ev.apply(X, fast).degenerate_triples, 0) << "trial " << trial;
    coupling::apply_reference(b.links, X, ref);
    EXPECT_LT((fast - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff())
        << "trial " << trial;
  }

  // Sphere tree with an association for every sphere; the bundle round-trips.
  ASSERT_GT(b.spheres.num_nodes(), 1);
  EXPECT_NO_THROW(collision::validate(b.spheres));
  for (int i = 0; i < b.spheres.num_nodes(); ++i)
    EXPECT_GT(b.spheres.assoc_offset[i + 1], b.spheres.assoc_offset[i]) << "sphere " << i;
  const auto dir = std::filesystem::path(::testing::TempDir()) / "icd_e2e_dragon";
  std::filesystem::remove_all(dir);
  coupling::write_asset_bundle(dir, b);
  const coupling::AssetBundle loaded = coupling::read_asset_bundle(dir);
  EXPECT_TRUE(loaded.links.coeffs == b.links.coeffs);
  EXPECT_TRUE(loaded.coarse.V == b.coarse.V);
  for (const auto& st : r.times)
    std::cout << "  " << st.stage << ": " << st.seconds << " s (cpu " << st.cpu_seconds << " s)\n";
}

}  // namespace
}  // namespace icd::mesh
