// Our evaluation against the reference toolkit's own. makeTreeMedial
// (Bradshaw's Sphere Tree Construction Toolkit, -testerLevels 2 -eval)
// appends to every tree it writes its evaluation: per level the number of
// spheres and the worst and mean error measured on its 42 sphere points, in
// units where the model's longest side is 2000. Evaluated in the toolkit's
// probe frame, the trees it wrote for the dragon and the bunny (committed
// as reference data, experiments/studies/spheretree/results/reference/) must give
// those numbers: an independent check of our inside tests, distances and
// probe frame. The corpus hand (issue 30) too: its toolkit tree has one leaf
// written with radius 0.000000 that the toolkit's evaluation skips (its
// count is ours minus one; the dragon's and bunny's such leaves it counts).
// A model whose mesh has not been fetched (scripts/fetch_meshes.sh,
// scripts/fetch_corpus.sh) is skipped.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <icd/collision/sph_io.hpp>
#include <icd/config.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/spheres/evaluation.hpp>

namespace {

namespace fs = std::filesystem;

struct ToolkitLevel {
  int num = 0;
  double worst = 0, mean = 0;
};

/// The per-level evaluation makeTreeMedial appends after "Evaluation :".
std::vector<ToolkitLevel> toolkit_evaluation(const fs::path& sph) {
  std::ifstream in(sph);
  std::vector<ToolkitLevel> levels;
  bool started = false;
  for (std::string word; in >> word;) {
    if (word == "Evaluation") started = true;
    if (!started) continue;
    if (word == "Level") levels.emplace_back();
    std::string colon;
    if (word == "Num") in >> colon >> levels.back().num;
    if (word == "Worst") in >> colon >> levels.back().worst;
    if (word == "Mean") in >> colon >> levels.back().mean;
  }
  return levels;
}

TEST(ReferenceToolkit, OurEvaluationInItsFrameGivesItsOwnNumbers) {
  const char* env = std::getenv("ICD_DATA_DIR");
  const fs::path data = fs::path(env ? env : ICD_DATA_DIR);
  const fs::path reference =
      fs::path(ICD_SOURCE_DIR) / "experiments/studies/spheretree/results/reference";
  int checked = 0;
  for (const auto& [mesh_file, tree_file] :
       {std::pair{"ChineseDragon-10kv.off", "dragon_readme-medial.sph"},
        std::pair{"bunny00.off", "bunny_readme-medial.sph"},
        std::pair{"corpus/hand.off", "hand_readme-medial.sph"}}) {
    SCOPED_TRACE(tree_file);
    const fs::path mesh_path = data / mesh_file;
    if (!fs::exists(mesh_path)) continue;
    const fs::path sph = reference / tree_file;
    const icd::SurfaceMesh mesh = icd::read_surface_mesh(mesh_path);
    icd::collision::SphereTree tree = icd::collision::read_sph(sph.string());
    // makeTreeMedial writes its trees centred on the bounding-box centre.
    const Eigen::Vector3d centre =
        0.5 * (mesh.V.colwise().minCoeff() + mesh.V.colwise().maxCoeff());
    for (auto& s : tree.spheres) s.x += centre.x(), s.y += centre.y(), s.z += centre.z();
    tree.rest_spheres = tree.spheres;

    const std::vector<ToolkitLevel> expected = toolkit_evaluation(sph);
    ASSERT_EQ(expected.size(), 4u);
    icd::mesh::EvaluationOptions options;
    options.probe_frame = icd::mesh::toolkit_probe_frame();
    options.probe_rotations = 0;
    options.shell_samples = 0;
    options.coverage_spacing = 20.0;  // coverage is not compared here
    const auto toolkit_frame = icd::mesh::evaluate_sphere_tree(mesh, tree, options);
    ASSERT_EQ(toolkit_frame.size(), 4u);
    for (size_t l = 0; l < 4; ++l) {
      SCOPED_TRACE("level " + std::to_string(l));
      // Spheres of radius 0 (centres on the surface, error < 1e-3): the
      // toolkit may have left them out of its count and mean.
      const int begin = tree.level_offset[l], end = tree.level_offset[l + 1];
      int zero = 0;
      for (int i = begin; i < end; ++i) {
        if (tree.spheres[static_cast<size_t>(i)].r == 0) ++zero;
      }
      const int ours = toolkit_frame[l].num_spheres;
      EXPECT_TRUE(ours == expected[l].num || ours - zero == expected[l].num)
          << ours << " spheres (" << zero << " of radius 0), the toolkit's " << expected[l].num;
      // The toolkit computes in single precision and prints 3 decimals
      // (measured: within 5e-4 at every level).
      EXPECT_NEAR(toolkit_frame[l].worst_error_42, expected[l].worst,
                  1e-3 + 1e-5 * expected[l].worst);
      const double mean = toolkit_frame[l].mean_error_42 * ours / std::max(1, expected[l].num);
      EXPECT_NEAR(mean, expected[l].mean, 1e-3 + 1e-5 * expected[l].mean);
    }
    // The tree was fitted against those 42 points: in our frame (another 42
    // directions) its leaves stick out much further.
    options.probe_frame.setIdentity();
    const auto our_frame = icd::mesh::evaluate_sphere_tree(mesh, tree, options);
    EXPECT_GT(our_frame[3].mean_error_42, toolkit_frame[3].mean_error_42 + 3.0);
    EXPECT_GT(our_frame[3].worst_error_42, toolkit_frame[3].worst_error_42 + 20.0);
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "the meshes are missing (run scripts/fetch_meshes.sh)";
}

}  // namespace
