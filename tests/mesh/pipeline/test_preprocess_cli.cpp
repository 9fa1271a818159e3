// The icd-preprocess program's sphere-tree options: --sph writes the
// bundle's tree as .sph (read back equal to the bundle's, covering every
// vertex at every level; the octree builder, as a medial build of even a
// small sphere takes over 10 s at the fits' sample spacings), and
// --sphere-fit refuses an unknown fit, and contradictory options are refused,
// before any work.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <icd/collision/sph_io.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/surface_writer.hpp>
#include "mesh/program_run.hpp"

namespace {

namespace fs = std::filesystem;

#ifdef ICD_PREPROCESS
using icd::test::ProgramRun;

ProgramRun run_preprocess(const std::string& args, const fs::path& dir) {
  return icd::test::run_program(ICD_PREPROCESS, args, dir);
}

TEST(PreprocessCli, WritesTheBundlesTreeAsSph) {
  const fs::path dir = fs::temp_directory_path() / "icd_test_preprocess_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  icd::write_off(dir / "sphere.off", icd::make_icosphere(2));
  const fs::path bundle = dir / "bundle", sph = dir / "tree.sph";
  const ProgramRun run = run_preprocess(
      (dir / "sphere.off").string() + " -o " + bundle.string() +
          " --coarse-tets 200 --sphere-depth 2 --sphere-branching 4 --spheres octree --sph " +
          sph.string() + " --no-hausdorff -q",
      dir);
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_FALSE(fs::exists(sph.string() + ".part"));
  const icd::coupling::AssetBundle b = icd::coupling::read_asset_bundle(bundle);
  const icd::collision::SphereTree tree = icd::collision::read_sph(sph.string());
  ASSERT_EQ(tree.num_nodes(), b.spheres.num_nodes());
  ASSERT_EQ(tree.num_levels(), 3);
  for (int i = 0; i < tree.num_nodes(); ++i) {
    const auto &s = tree.spheres[i], &t = b.spheres.rest_spheres[i];
    EXPECT_NEAR((s.center() - t.center()).norm(), 0.0, 1e-9) << "node " << i;
    EXPECT_NEAR(s.r, t.r, 1e-9) << "node " << i;
    EXPECT_EQ(tree.child_count[i], b.spheres.child_count[i]) << "node " << i;
  }
  for (int l = 0; l < tree.num_levels(); ++l) {
    for (Eigen::Index v = 0; v < b.dense.V.rows(); ++v) {
      bool covered = false;
      for (int i = tree.level_offset[l]; i < tree.level_offset[l + 1] && !covered; ++i)
        covered = (b.dense.V.row(v).transpose() - tree.spheres[i].center()).norm() <=
                  tree.spheres[i].r + 1e-9;
      EXPECT_TRUE(covered) << "vertex " << v << " at level " << l;
    }
  }
  fs::remove_all(dir);
}

TEST(PreprocessCli, RefusesAnUnknownFitBeforeAnyWork) {
  const fs::path dir = fs::temp_directory_path() / "icd_test_preprocess_cli_bad";
  fs::remove_all(dir);
  fs::create_directories(dir);
  icd::write_off(dir / "sphere.off", icd::make_icosphere(1));
  const ProgramRun run = run_preprocess(
      (dir / "sphere.off").string() + " -o " + (dir / "bundle").string() + " --sphere-fit tight",
      dir);
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("--sphere-fit: must be light, full or shell, got 'tight'"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(fs::exists(dir / "bundle"));
  const ProgramRun none =
      run_preprocess((dir / "sphere.off").string() + " -o " + (dir / "bundle").string() +
                         " --no-spheres --sph x.sph",
                     dir);
  EXPECT_EQ(none.status, 2) << none.output;
  EXPECT_NE(none.output.find("--sph needs a sphere tree"), std::string::npos) << none.output;
  fs::remove_all(dir);
}

// Options that contradict each other are refused naming both, before any work
// (before, the later of --simplify-faces / --simplify-ratio silently won).
TEST(PreprocessCli, RefusesContradictoryOptionsNamingBoth) {
  const fs::path dir = fs::temp_directory_path() / "icd_test_preprocess_cli_contradict";
  fs::remove_all(dir);
  fs::create_directories(dir);
  icd::write_off(dir / "sphere.off", icd::make_icosphere(1));
  for (const std::string& options :
       {"--simplify-faces 100 --simplify-ratio 0.5", "--simplify-ratio 0.5 --simplify-faces 100",
        "--spheres octree --sphere-fit full", "--sphere-fit shell --no-spheres"}) {
    const ProgramRun run = run_preprocess(
        (dir / "sphere.off").string() + " -o " + (dir / "bundle").string() + " " + options, dir);
    EXPECT_EQ(run.status, 2) << options << ": " << run.output;
    EXPECT_NE(run.output.find("contradict each other"), std::string::npos) << run.output;
    const std::string first = options.substr(0, options.find(' '));
    EXPECT_NE(run.output.find(first), std::string::npos) << run.output;
    EXPECT_FALSE(fs::exists(dir / "bundle")) << options;
  }
  fs::remove_all(dir);
}

// --max-wrap-distance: a fraction of the diagonal in (0, 1]; anything else is
// refused naming the option, before any work.
TEST(PreprocessCli, MaxWrapDistanceIsValidated) {
  const fs::path dir = fs::temp_directory_path() / "icd_test_preprocess_cli_wrap_distance";
  fs::remove_all(dir);
  fs::create_directories(dir);
  icd::write_off(dir / "sphere.off", icd::make_icosphere(1));
  const std::string head = (dir / "sphere.off").string() + " -o " + (dir / "bundle").string();
  for (const char* bad : {"0", "-0.1", "1.5", "nan", "abc"}) {
    const ProgramRun run = run_preprocess(head + " --max-wrap-distance " + bad, dir);
    EXPECT_EQ(run.status, 2) << bad << ": " << run.output;
    EXPECT_NE(run.output.find("--max-wrap-distance "), std::string::npos) << run.output;
    EXPECT_TRUE(run.output.find(std::string("must be in (0, 1], got '") + bad + "'") !=
                    std::string::npos ||
                run.output.find(std::string("expects a finite number, got '") + bad + "'") !=
                    std::string::npos)
        << run.output;
    EXPECT_FALSE(fs::exists(dir / "bundle")) << bad;
  }
  // A valid value is taken: a wrap of the sphere at alpha 0.3 lies more than
  // 1e-3 of the diagonal from it, so that limit refuses it, naming the option.
  const ProgramRun strict = run_preprocess(
      head + " --wrap always --wrap-alpha 0.3 --max-wrap-distance 0.001 --no-spheres", dir);
  EXPECT_EQ(strict.status, 1) << strict.output;
  EXPECT_NE(strict.output.find("(limit 0.1 %, --max-wrap-distance 0.001)"), std::string::npos)
      << strict.output;
  EXPECT_FALSE(fs::exists(dir / "bundle"));
  fs::remove_all(dir);
}
#endif

}  // namespace
