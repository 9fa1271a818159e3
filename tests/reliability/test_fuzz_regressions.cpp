// Replays the libFuzzer regression inputs (tests/fuzz/regressions/<target>/)
// and the seed corpora (tests/fuzz/corpus/<target>/) through the same entry
// points as the fuzz targets. Oracle: the documented contract of each reader
// -- a valid result (postconditions checked) or icd::InputError /
// icd::ParameterError; any other exception fails, a crash fails the run.
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <typeinfo>
#include <vector>

#include <icd/collision/sph_io.hpp>
#include "experiments/runner/scene.hpp"
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/vtu_reader.hpp>
#include "tests/fuzz/bundle_fixture.hpp"

namespace icd {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void check_surface(const SurfaceMesh& m, const std::string& file) {
  ASSERT_GE(m.V.rows(), 1) << file;
  ASSERT_GE(m.F.rows(), 1) << file;
  EXPECT_TRUE(m.V.allFinite()) << file;
  EXPECT_GE(m.F.minCoeff(), 0) << file;
  EXPECT_LT(m.F.maxCoeff(), m.V.rows()) << file;
}

const fs::path& bundle_folder() {
  static const fs::path dir = [] {
    const fs::path d = fs::path(::testing::TempDir()) / "icd_reliability_bundle";
    fs::remove_all(d);
    fuzz::write_fixture_bundle(d);
    return d;
  }();
  return dir;
}

// Feeds `bytes` to the reader of `target`; true when it was accepted.
bool replay(const std::string& target, const std::string& bytes, const std::string& file) {
  if (target == "off" || target == "obj" || target == "ply" || target == "stl") {
    SurfaceMesh m = target == "off"   ? parse_off(bytes, file)
                    : target == "obj" ? parse_obj(bytes, file)
                    : target == "ply" ? parse_ply(bytes, file)
                                      : parse_stl(bytes, file);
    check_surface(m, file);
  } else if (target == "vtu") {
    const VtuData d = parse_vtu(bytes, file);
    EXPECT_TRUE(d.points.allFinite()) << file;
    EXPECT_EQ(d.offsets.size(), d.types.size()) << file;
    for (int64_t c : d.connectivity) EXPECT_TRUE(c >= 0 && c < d.points.rows()) << file;
  } else if (target == "sph") {
    std::istringstream in(bytes);
    const collision::SphereTree t = collision::read_sph(in, file);
    EXPECT_NO_THROW(collision::validate(t)) << file;
  } else if (target == "bundle") {
    const auto* p = reinterpret_cast<const uint8_t*>(bytes.data());
    const coupling::AssetBundle b = fuzz::load_mutated_bundle(bundle_folder(), p, bytes.size());
    EXPECT_EQ(b.links.nodes.rows(), b.dense.V.rows()) << file;
    if (b.spheres.num_nodes() > 0) {
      EXPECT_NO_THROW(collision::validate(b.spheres)) << file;
    }
  } else if (target == "scene") {
    const runner::Json j = runner::parse_json(bytes, file);
    const runner::Scene s = runner::parse_scene(j, file, "/nonexistent");
    EXPECT_GE(s.frames, 1) << file;
  } else {
    ADD_FAILURE() << "unknown fuzz target folder " << target;
  }
  return true;
}

struct Counts {
  int files = 0, accepted = 0, refused = 0;
};

Counts replay_folder(const fs::path& root) {
  Counts c;
  if (!fs::exists(root)) return c;
  for (const auto& dir : fs::directory_iterator(root)) {
    if (!dir.is_directory()) continue;
    const std::string target = dir.path().filename().string();
    for (const auto& f : fs::directory_iterator(dir.path())) {
      if (!f.is_regular_file() || f.path().filename().string()[0] == '.') continue;
      const std::string file = f.path().string();
      ++c.files;
      try {
        replay(target, slurp(f.path()), file);
        ++c.accepted;
      } catch (const InputError& e) {
        ++c.refused;
        EXPECT_FALSE(std::string(e.what()).empty()) << file;
      } catch (const ParameterError&) {
        ++c.refused;
      } catch (const std::exception& e) {
        ADD_FAILURE() << file << ": undocumented exception " << typeid(e).name() << ": "
                      << e.what();
      }
    }
  }
  return c;
}

// Replays the kept inputs under `root` (one folder per fuzz target); a
// missing or empty folder is a failure (the check would pass on nothing).
void check_kept_inputs(const fs::path& root) {
  if (!fs::is_directory(root)) {
    ADD_FAILURE() << root << " does not exist: no kept input was replayed";
    return;
  }
  const Counts c = replay_folder(root);
  EXPECT_GE(c.files, 1) << root << " holds no kept input";
  ::testing::Test::RecordProperty("files", c.files);
  std::cout << "regressions: " << c.files << " files, " << c.accepted << " accepted, " << c.refused
            << " refused\n";
}

TEST(FuzzRegressions, EveryKeptInputGivesAResultOrADocumentedError) {
  check_kept_inputs(fs::path(ICD_FUZZ_DIR) / "regressions");
}

// The check must not pass on nothing: a missing (or empty) folder fails.
TEST(FuzzRegressions, AMissingFolderFailsTheCheck) {
  EXPECT_NONFATAL_FAILURE(check_kept_inputs("/nonexistent/icd_fuzz/regressions"),
                          "/nonexistent/icd_fuzz/regressions");
}

TEST(FuzzRegressions, EverySeedIsAcceptedOrRefusedCleanly) {
  const Counts c = replay_folder(fs::path(ICD_FUZZ_DIR) / "corpus");
  // The seeds are valid files of each format: most of them must be accepted,
  // or the fuzz targets start from nothing.
  EXPECT_GE(c.files, 16);
  EXPECT_GE(c.accepted, c.files - 1);
}

}  // namespace
}  // namespace icd
