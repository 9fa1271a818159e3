// Google Benchmark of the collision module: sphere tests per second, update
// cost per sphere, full traversals, and query time per budget (two
// overlapping dragons, octree trees). Timings are for comparison within one
// run; nothing here gates a build.
#include <benchmark/benchmark.h>

#include "experiments/common/benchmark_main.hpp"

#include <memory>
#include <random>

#include <icd/collision/sphere_update.hpp>
#include <icd/collision/traversal.hpp>
#include "experiments/studies/collision/workloads.hpp"

using namespace icd::collision;
using namespace icd::collision::experiments;

namespace {

struct DragonScene {
  Object a, b;
  icd::MatX3d xa, xb;
};

DragonScene* dragons(int levels) {
  static std::unique_ptr<DragonScene> cache[8];
  if (!cache[levels]) {
    auto s = std::make_unique<DragonScene>();
    s->a = load_object("ChineseDragon-10kv.off", {0, 0, 0}, levels);
    s->b = load_object("ChineseDragon-10kv.off", {0.45, 0.15, 0.05}, levels);
    s->xa = deform(s->a.coarse_rest, 0.05, 0.3);
    s->xb = deform(s->b.coarse_rest, 0.05, 1.3);
    // Deformed configuration for every benchmark, whatever runs first.
    update_spheres(s->a.tree, s->a.coarse_rest, s->xa, {});
    update_spheres(s->b.tree, s->b.coarse_rest, s->xb, {});
    cache[levels] = std::move(s);
  }
  return cache[levels].get();
}

void BM_SphereOverlapTest(benchmark::State& state) {
  std::mt19937 rng(0);
  std::uniform_real_distribution<double> u(0, 1), ur(0.01, 0.2);
  std::vector<Sphere> s(4096);
  for (Sphere& sp : s) sp = {u(rng), u(rng), u(rng), ur(rng)};
  std::vector<std::pair<int, int>> pairs(1 << 16);
  for (auto& p : pairs) p = {int(rng() % s.size()), int(rng() % s.size())};
  int64_t hits = 0;
  for (auto _ : state) {
    for (const auto& [i, j] : pairs) hits += overlap(s[i], s[j]);
    benchmark::DoNotOptimize(hits);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(pairs.size()));
  state.counters["overlap_fraction"] = double(hits) / (double(state.iterations()) * pairs.size());
}
BENCHMARK(BM_SphereOverlapTest);

void BM_SphereUpdate(benchmark::State& state) {
  DragonScene* d;
  try {
    d = dragons(static_cast<int>(state.range(1)));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  SphereUpdateOptions o;
  o.mode = state.range(0) == 0 ? SphereUpdateMode::PaperRatio : SphereUpdateMode::DisplacementBound;
  icd::collision::SphereTree tree = d->a.tree;  // a copy: the shared scene stays as it is
  for (auto _ : state) {
    update_spheres(tree, d->a.coarse_rest, d->xa, o);
    benchmark::ClobberMemory();
  }
  const int n = d->a.tree.num_nodes();
  state.SetItemsProcessed(state.iterations() * n);  // items = spheres
  state.counters["spheres"] = n;
}
BENCHMARK(BM_SphereUpdate)->ArgsProduct({{0, 1}, {4, 5}})->ArgNames({"conservative", "levels"});

void BM_FullTraversal(benchmark::State& state) {
  DragonScene* d;
  try {
    d = dragons(static_cast<int>(state.range(1)));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  CollisionRequest r =
      state.range(0) == 0
          ? CollisionRequest::paper_reference(std::numeric_limits<double>::infinity())
          : CollisionRequest{};
  if (state.range(0) == 2) r.mode = TraversalMode::DepthFirst;
  if (state.range(0) == 3) r.mode = TraversalMode::Priority;
  CollisionResult res;
  for (auto _ : state) collide(d->a.tree, d->b.tree, r, res);
  state.counters["tests"] = double(res.tests);
  state.counters["leaf_pairs"] = double(res.colliding.size());
  state.counters["peak"] = double(res.peak_list_size);
  state.SetItemsProcessed(state.iterations() * res.tests);  // items = sphere tests
}
// 0: literal Fig. 7, 1: fast FIFO, 2: fast DFS, 3: priority
BENCHMARK(BM_FullTraversal)->ArgsProduct({{0, 1, 2, 3}, {4, 5}})->ArgNames({"mode", "levels"});

void BM_QueryBudget(benchmark::State& state) {
  DragonScene* d;
  try {
    d = dragons(6);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  CollisionRequest r;
  r.budget_seconds = state.range(0) * 1e-6;
  CollisionResult res;
  int64_t interrupted = 0, tests = 0;
  for (auto _ : state) {
    collide(d->a.tree, d->b.tree, r, res);
    interrupted += res.interrupted;
    tests += res.tests;
  }
  state.counters["interrupted"] = double(interrupted) / state.iterations();
  state.counters["tests"] = double(tests) / state.iterations();
  state.counters["completed_level"] = res.completed_level;
}
BENCHMARK(BM_QueryBudget)
    ->Arg(10)
    ->Arg(30)
    ->Arg(100)
    ->Arg(300)
    ->Arg(1000)
    ->Unit(benchmark::kMicrosecond);

}  // namespace

ICD_BENCHMARK_MAIN("bench_collision",
                   "Google Benchmark of the collision module: sphere tests/s, update per sphere, traversals, query time per budget.");
