// Google Benchmark of the coupling layer: rigid links (paper Eqs. 9-10) vs
// the barycentric embedding (sparse W * x), per dense vertex, on a dense
// icosphere over a structured coarse ball; and the contact response per pair.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "coupling/barycentric_embedding.hpp"
#include "coupling/contact_response.hpp"
#include "coupling/rigid_links.hpp"
#include "experiments/runner/object_asset.hpp"

namespace {

using namespace icd;

struct Fixture {
  runner::ObjectAsset asset;
  coupling::BarycentricEmbedding embedding;
  MatX3d deformed;
  explicit Fixture(int subdivisions) {
    runner::PrimitiveSpec spec;
    spec.subdivisions = subdivisions;
    spec.cells = 8;
    asset = runner::make_primitive_asset(spec, 3);
    embedding = coupling::build_barycentric_embedding(asset.dense.V, asset.coarse.V, asset.coarse.T);
    std::mt19937 rng(0);
    std::normal_distribution<double> n(0.0, 1e-3);
    deformed = asset.coarse.V;
    for (int i = 0; i < deformed.rows(); ++i)
      for (int k = 0; k < 3; ++k) deformed(i, k) += n(rng);
  }
};

const Fixture& fixture(int subdivisions) {
  static std::vector<std::unique_ptr<Fixture>> cache(8);
  if (!cache[subdivisions]) cache[subdivisions] = std::make_unique<Fixture>(subdivisions);
  return *cache[subdivisions];
}

void BM_RigidLinks(benchmark::State& state) {
  const Fixture& f = fixture(static_cast<int>(state.range(0)));
  MatX3d out(f.asset.dense.V.rows(), 3);
  for (auto _ : state) {
    coupling::apply(f.asset.links, f.deformed, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["dense_vertices"] = static_cast<double>(out.rows());
  state.counters["ns_per_vertex"] = benchmark::Counter(
      static_cast<double>(out.rows()), benchmark::Counter::kIsIterationInvariantRate |
                                           benchmark::Counter::kInvert);
}

void BM_Barycentric(benchmark::State& state) {
  const Fixture& f = fixture(static_cast<int>(state.range(0)));
  MatX3d out(f.asset.dense.V.rows(), 3);
  for (auto _ : state) {
    coupling::apply(f.embedding, f.deformed, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["dense_vertices"] = static_cast<double>(out.rows());
  state.counters["ns_per_vertex"] = benchmark::Counter(
      static_cast<double>(out.rows()), benchmark::Counter::kIsIterationInvariantRate |
                                           benchmark::Counter::kInvert);
}

// Contact response for every leaf pair of two overlapping trees.
void BM_ContactResponse(benchmark::State& state) {
  const Fixture& f = fixture(3);
  collision::CollisionResult r;
  const collision::SphereTree& t = f.asset.spheres;
  for (int i = t.level_offset[t.num_levels() - 1]; i < t.num_nodes(); ++i)
    r.colliding.push_back({i, i});
  MatX3d fa = MatX3d::Zero(f.asset.coarse.V.rows(), 3), fb = fa;
  for (auto _ : state) {
    coupling::apply_contact_forces(t, t, r, {}, fa, fb);
    benchmark::DoNotOptimize(fa.data());
  }
  state.counters["pairs"] = static_cast<double>(r.colliding.size());
  state.counters["ns_per_pair"] = benchmark::Counter(
      static_cast<double>(r.colliding.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_RigidLinks)->Arg(3)->Arg(5)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Barycentric)->Arg(3)->Arg(5)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ContactResponse)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
