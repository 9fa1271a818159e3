#include <gtest/gtest.h>

#include <CGAL/assertions.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/pipeline/bounded.hpp>
#include <icd/mesh/pipeline/preprocess.hpp>

namespace icd::mesh {
namespace {

// Expects `f` to throw StageError of `kind` whose message has every fragment.
template <class F>
void expect_stage_error(F f, StageError::Kind kind, std::initializer_list<const char*> fragments,
                        std::initializer_list<const char*> absent = {}) {
  try {
    f();
    ADD_FAILURE() << "no exception";
  } catch (const StageError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(static_cast<int>(e.kind()), static_cast<int>(kind)) << msg;
    for (const char* s : fragments) EXPECT_NE(msg.find(s), std::string::npos) << s << " in " << msg;
    for (const char* s : absent) EXPECT_EQ(msg.find(s), std::string::npos) << s << " in " << msg;
    std::cout << "  message: " << msg << "\n";
  }
}

TEST(Bounded, ReturnsTheResultAndForwardsInputErrors) {
  StageLimits l;
  StageUsage u;
  EXPECT_EQ(run_bounded("echo", l, [] { return std::string("abc\0def", 7); }, &u),
            std::string("abc\0def", 7));
  EXPECT_GE(u.cpu_seconds, 0.0);
  EXPECT_GT(u.peak_mb, 0.0);
  // A large answer (more than a pipe buffer) arrives whole.
  const std::string big(5 << 20, 'x');
  EXPECT_EQ(run_bounded("big", l, [&] { return big; }), big);
  EXPECT_THROW(run_bounded("in", l, []() -> std::string { throw InputError("in.off: bad"); }),
               InputError);
  EXPECT_THROW(run_bounded("par", l, []() -> std::string { throw ParameterError("x: bad"); }),
               ParameterError);
}

TEST(Bounded, CpuLimitNamesTheStageAndTheOption) {
  StageLimits l;
  l.cpu_seconds = 1;
  expect_stage_error(
      [&] {
        run_bounded("spin", l, [] {
          volatile double x = 0;
          for (;;) x = x + 1;
          return std::string();
        });
      },
      StageError::Kind::cpu_limit, {"'spin'", "CPU-time limit of 1 s", "--time-limit"});
}

TEST(Bounded, MemoryLimitNamesTheStageAndTheOption) {
  StageLimits l;
  l.memory_mb = 300;
  expect_stage_error(
      [&] {
        run_bounded("grow", l, [] {
          std::vector<std::vector<char>> hog;
          for (;;) hog.emplace_back(64 << 20, 1);
          return std::string();
        });
      },
      StageError::Kind::memory_limit, {"'grow'", "memory limit of 300 MB", "--memory-limit"});
}

TEST(Bounded, CgalFailuresAndTheirFilesStayInside) {
  const std::filesystem::path cwd = std::filesystem::current_path();
  expect_stage_error(
      [&] {
        run_bounded(
            "mesher", StageLimits{},
            [] {
              std::ofstream("dump-bug.c3t3") << "x";  // what Mesh_3 writes before it throws
              CGAL::assertion_fail("secret_expr", "Refine_facets_3.h", 859, "already inserted");
              return std::string();
            },
            nullptr, {}, "try --cell-size");
      },
      StageError::Kind::internal, {"'mesher'", "failed inside CGAL", "try --cell-size"},
      {"secret_expr", "Refine_facets_3", "already inserted", "CGAL ERROR"});
  EXPECT_FALSE(std::filesystem::exists(cwd / "dump-bug.c3t3"));
}

TEST(Bounded, CrashIsReportedNotPropagated) {
  expect_stage_error(
      [] {
        run_bounded("crash", StageLimits{}, []() -> std::string {
          std::abort();
        });
      },
      StageError::Kind::crashed, {"'crash'", "crashed"});
}

// The sphere of radius 1e-15 hung the mesher; every scale must give
// the same mesh (normalised coordinates, power-of-two scaling).
TEST(Bounded, PreprocessDoesNotDependOnScale) {
  PreprocessOptions o;
  o.sphere_builder = SphereBuilder::none;
  o.tetrahedralize.target_tets = 300;
  o.limits.cpu_seconds = 60;
  const SurfaceMesh unit = make_icosphere(2);
  std::vector<int> tets;
  std::vector<double> diagonals;
  for (double scale : {1e-15, 1.0, 1e30}) {
    SurfaceMesh m = unit;
    m.V *= scale;
    const PreprocessResult r = preprocess(m, o, {}, "sphere");
    tets.push_back(static_cast<int>(r.bundle.coarse.T.rows()));
    diagonals.push_back(r.bbox_diagonal / scale);
    EXPECT_NEAR(r.quality.total_volume / (scale * scale * scale), 4.0, 0.3);
    EXPECT_LT(r.hausdorff_dense_coarse / r.bbox_diagonal, 0.05);
  }
  EXPECT_NEAR(diagonals[0], diagonals[1], 1e-12 * diagonals[1]);
  EXPECT_NEAR(diagonals[2], diagonals[1], 1e-12 * diagonals[1]);
  // 1e-15 and 1e30 are not powers of two: the scaled input itself rounds, so
  // the meshes may differ by a few tets (not more).
  EXPECT_NEAR(tets[0], tets[1], 0.02 * tets[1]);
  EXPECT_NEAR(tets[2], tets[1], 0.02 * tets[1]);
}

TEST(Bounded, TetrahedralizeLimitNamesStageAndOptions) {
  TetrahedralizeOptions o;
  o.limits.cpu_seconds = 0.6;  // a pass gets 0.2 s: too little for 20000 tets
  o.target_tets = 20000;
  try {
    tetrahedralize_surface(make_icosphere(3), o);
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    std::cout << "  message: " << msg << "\n";
    EXPECT_NE(msg.find("tetrahedralize"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--time-limit"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--coarse-tets"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace icd::mesh
