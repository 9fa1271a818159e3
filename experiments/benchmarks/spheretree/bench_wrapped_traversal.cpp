// Full traversals of two copies of a wrapped sphere tree near contact, with
// and without CollisionRequest::parent_filter, measured in the same run.
//
// Scenes: the committed trees of experiments/studies/spheretree/results
// (ours: {dragon,bunny}_medial.sph; the reference toolkit's:
// reference/{dragon,bunny}_readme-medial.sph) on 32 approach poses of
// contact_tightness's kind (seed 1): the second copy turned by a random
// rotation and moved to 1 unit (longest side 2000) short of where the
// surfaces first touch, i.e. the hardest case for a sphere tree (every leaf
// pair reported is a false contact). One iteration runs the 32 queries.
// Counters: sphere tests and leaf pairs per query. Compare filter=1 against
// filter=0 of the same tree and mode, within one run. BM_NearContactTestBudget:
// the same queries interrupted by a budget of sphere tests.
// Run: <build>/bin/bench_wrapped_traversal --benchmark_repetitions=7
//          --benchmark_enable_random_interleaving=true (the machine is noisy)
// Recorded results: experiments/studies/spheretree/results/bench_parent_filter.txt
// (README.md there, "Parent filter").
#include <benchmark/benchmark.h>

#include "experiments/common/benchmark_main.hpp"

#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <icd/collision/traversal.hpp>
#include "experiments/studies/spheretree/approach.hpp"
#include "experiments/studies/spheretree/tree_report.hpp"
#include <icd/config.hpp>
#include <icd/mesh/io/surface_reader.hpp>

namespace {

using icd::collision::SphereTree;

struct Workload {
  SphereTree a;
  std::vector<SphereTree> b;  // the moved copies, one per pose
};

constexpr int kPoses = 32;
constexpr double kGap = 1.0;  // normalized units short of touching

// Trees: 0 = ours (the table's default), 1 = the reference toolkit's.
const char* tree_file(int model, int tree) {
  static const char* files[2][2] = {{"dragon_medial.sph", "reference/dragon_readme-medial.sph"},
                                    {"bunny_medial.sph", "reference/bunny_readme-medial.sph"}};
  return files[model][tree];
}

const Workload* workload(benchmark::State& state, int model, int tree) {
  static std::map<int, std::unique_ptr<Workload>> cache;
  const int key = 2 * model + tree;
  if (auto it = cache.find(key); it != cache.end()) return it->second.get();
  const char* env = std::getenv("ICD_DATA_DIR");
  const std::filesystem::path data(env && *env ? env : ICD_DATA_DIR);
  const auto mesh_path = data / (model == 0 ? "ChineseDragon-10kv.off" : "bunny00.off");
  const auto sph = std::filesystem::path(ICD_SOURCE_DIR) / "experiments/studies/spheretree/results" /
                   tree_file(model, tree);
  if (!std::filesystem::exists(mesh_path) || !std::filesystem::exists(sph)) {
    state.SkipWithError("mesh or tree missing (scripts/fetch_meshes.sh)");
    return nullptr;
  }
  const icd::SurfaceMesh mesh = icd::read_surface_mesh(mesh_path);
  auto w = std::make_unique<Workload>();
  w->a = icd::experiments::read_sph_for_mesh(sph.string(), mesh, tree == 1);
  const double to_2000 = icd::experiments::to_normalized_units(mesh);
  icd::experiments::SelfApproach surfaces(mesh.V, mesh.F);
  icd::experiments::RandomApproachPoses poses(1, icd::experiments::bounding_box_centre(mesh));
  while (static_cast<int>(w->b.size()) < kPoses) {
    const auto pose = poses.next();
    const double start = icd::experiments::last_leaf_overlap(w->a, w->a, pose) + 1.0 / to_2000;
    const auto touching = icd::experiments::find_touching(
        [&](double t) { return surfaces.meets(pose, t); }, start, 0.5 / to_2000, 1e-4 / to_2000);
    if (!touching.found) continue;
    w->b.push_back(icd::experiments::moved(w->a, pose, touching.apart + kGap / to_2000));
  }
  return cache.emplace(key, std::move(w)).first->second.get();
}

// Args: filter (0/1; first, so that the two runs of a configuration are
// adjacent in time on a noisy machine), model (0 dragon, 1 bunny), tree (0
// ours, 1 reference), mode (0 FIFO, 1 depth-first, 2 priority).
void BM_NearContact(benchmark::State& state) {
  const Workload* w =
      workload(state, static_cast<int>(state.range(1)), static_cast<int>(state.range(2)));
  if (!w) return;
  icd::collision::CollisionRequest r;
  r.mode = state.range(3) == 0   ? icd::collision::TraversalMode::BreadthFirstFifo
           : state.range(3) == 1 ? icd::collision::TraversalMode::DepthFirst
                                 : icd::collision::TraversalMode::Priority;
  r.parent_filter = state.range(0) != 0;
  icd::collision::CollisionResult res;
  int64_t tests = 0, pairs = 0;
  for (auto _ : state) {
    for (const SphereTree& b : w->b) {
      icd::collision::collide(w->a, b, r, res);
      tests += res.tests;
      pairs += static_cast<int64_t>(res.colliding.size());
    }
  }
  const double queries = static_cast<double>(state.iterations()) * kPoses;
  state.counters["tests"] = static_cast<double>(tests) / queries;
  state.counters["leaf_pairs"] = static_cast<double>(pairs) / queries;
  state.SetItemsProcessed(state.iterations() * kPoses);  // items = queries
}
BENCHMARK(BM_NearContact)
    ->ArgsProduct({{0, 1}, {0, 1}, {0, 1}, {0, 1, 2}})
    ->ArgNames({"filter", "model", "tree", "mode"})
    ->Unit(benchmark::kMicrosecond);

// The same queries under a budget of sphere tests (fast FIFO): what an
// interrupted query answers. Args: model, tree, budget (tests), filter.
// Counters per query: reported pairs (colliding + untested; fewer is
// tighter), completed level (deeper is tighter), interrupted share.
void BM_NearContactTestBudget(benchmark::State& state) {
  const Workload* w =
      workload(state, static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  if (!w) return;
  icd::collision::CollisionRequest r;
  r.budget_tests = state.range(2);
  r.parent_filter = state.range(3) != 0;
  icd::collision::CollisionResult res;
  int64_t reported = 0, level = 0, interrupted = 0;
  for (auto _ : state) {
    for (const SphereTree& b : w->b) {
      icd::collision::collide(w->a, b, r, res);
      reported += static_cast<int64_t>(res.colliding.size() + res.untested.size());
      level += res.completed_level;
      interrupted += res.interrupted ? 1 : 0;
    }
  }
  const double queries = static_cast<double>(state.iterations()) * kPoses;
  state.counters["reported"] = static_cast<double>(reported) / queries;
  state.counters["level"] = static_cast<double>(level) / queries;
  state.counters["interrupted"] = static_cast<double>(interrupted) / queries;
}
BENCHMARK(BM_NearContactTestBudget)
    ->ArgsProduct({{0, 1}, {0, 1}, {100, 200}, {0, 1}})
    ->ArgNames({"model", "tree", "budget", "filter"})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

ICD_BENCHMARK_MAIN("bench_wrapped_traversal",
                   "Google Benchmark: full traversals of two wrapped sphere trees near contact, with and without the parent filter.");
