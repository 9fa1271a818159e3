// Google Benchmark of the coupling layer, per dense vertex: the rigid links
// (paper Eqs. 9-10) evaluated one link at a time (apply_reference), by the
// LinkEvaluator (one frame per node triple), by the free apply() (which builds
// an evaluator each call), the origin map of Eq. 1 alone as a sparse product,
// and the barycentric embedding (sparse W * x) as the baseline. Objects: dense
// icospheres over a structured coarse ball (generated), and every bunny and
// dragon asset bundle in <repo>/assets (named by folder). Also the contact
// response per pair. Summarise repetitions with summarise_bench.py.
#include <benchmark/benchmark.h>

#include "experiments/common/benchmark_main.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <icd/coupling/asset_bundle.hpp>
#include <icd/coupling/barycentric_embedding.hpp>
#include <icd/coupling/contact_response.hpp>
#include <icd/coupling/link_evaluator.hpp>
#include <icd/coupling/rigid_links.hpp>
#include "experiments/runner/object_asset.hpp"
#include <icd/coupling/primitive_asset.hpp>
#include <icd/config.hpp>

namespace {

using namespace icd;

struct Fixture {
  runner::ObjectAsset asset;
  coupling::BarycentricEmbedding embedding;
  Eigen::SparseMatrix<double, Eigen::RowMajor> origin;
  MatX3d deformed;

  // Deformed state: a rotation about the centroid plus Gaussian noise of
  // 1e-3 x the bounding-box diagonal on every coarse node (fixed seed).
  explicit Fixture(runner::ObjectAsset a) : asset(std::move(a)) {
    embedding =
        coupling::build_barycentric_embedding(asset.dense.V, asset.coarse.V, asset.coarse.T);
    origin = coupling::origin_matrix(asset.links);
    const MatX3d& X = asset.coarse.V;
    const Eigen::RowVector3d c = X.colwise().mean();
    const double diag = (X.colwise().maxCoeff() - X.colwise().minCoeff()).norm();
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(0.6, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    std::mt19937 rng(0);
    std::normal_distribution<double> n(0.0, 1e-3 * diag);
    deformed = ((X.rowwise() - c) * R.transpose()).rowwise() + c;
    for (int i = 0; i < deformed.rows(); ++i)
      for (int k = 0; k < 3; ++k) deformed(i, k) += n(rng);
  }
};

std::map<std::string, std::unique_ptr<Fixture>>& fixtures() {
  static std::map<std::string, std::unique_ptr<Fixture>> f;
  return f;
}

runner::ObjectAsset sphere_asset(int subdivisions) {
  coupling::PrimitiveSpec spec;
  spec.subdivisions = subdivisions;
  spec.cells = 8;
  return coupling::make_primitive_asset(spec, 3);
}

void set_per_vertex(benchmark::State& state, const Fixture& f) {
  const double n = static_cast<double>(f.asset.dense.V.rows());
  state.counters["dense_vertices"] = n;
  state.counters["ns_per_vertex"] = benchmark::Counter(
      n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_LinksReference(benchmark::State& state, const Fixture* f) {
  MatX3d out(f->asset.dense.V.rows(), 3);
  for (auto _ : state) {
    coupling::apply_reference(f->asset.links, f->deformed, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  set_per_vertex(state, *f);
}

void BM_LinksEvaluator(benchmark::State& state, const Fixture* f) {
  coupling::LinkEvaluator ev(f->asset.links);
  MatX3d out(f->asset.dense.V.rows(), 3);
  for (auto _ : state) {
    ev.apply(f->deformed, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  set_per_vertex(state, *f);
  state.counters["triples"] = ev.num_triples();
}

void BM_LinksApplyWrapper(benchmark::State& state, const Fixture* f) {
  MatX3d out(f->asset.dense.V.rows(), 3);
  for (auto _ : state) {
    coupling::apply(f->asset.links, f->deformed, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  set_per_vertex(state, *f);
}

void BM_OriginSparse(benchmark::State& state, const Fixture* f) {
  MatX3d out(f->asset.dense.V.rows(), 3);
  for (auto _ : state) {
    out.noalias() = f->origin * f->deformed;
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  set_per_vertex(state, *f);
}

void BM_Barycentric(benchmark::State& state, const Fixture* f) {
  MatX3d out(f->asset.dense.V.rows(), 3);
  for (auto _ : state) {
    coupling::apply(f->embedding, f->deformed, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  set_per_vertex(state, *f);
}

// Contact response for every leaf pair of two overlapping trees.
void BM_ContactResponse(benchmark::State& state, const Fixture* f) {
  collision::CollisionResult r;
  const collision::SphereTree& t = f->asset.spheres;
  for (int i = t.level_offset[t.num_levels() - 1]; i < t.num_nodes(); ++i)
    r.colliding.push_back({i, i});
  MatX3d fa = MatX3d::Zero(f->asset.coarse.V.rows(), 3), fb = fa;
  for (auto _ : state) {
    coupling::apply_contact_forces(t, t, r, {}, fa, fb);
    benchmark::DoNotOptimize(fa.data());
  }
  state.counters["pairs"] = static_cast<double>(r.colliding.size());
  state.counters["ns_per_pair"] = benchmark::Counter(
      static_cast<double>(r.colliding.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// The asset bundle folders in <repo>/assets whose names start with `prefix`,
// sorted by name (the folder name ends with a hash of the preprocessing input).
std::vector<std::filesystem::path> find_bundles(const std::string& prefix) {
  const std::filesystem::path dir = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
  std::vector<std::filesystem::path> found;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.is_directory() && e.path().filename().string().rfind(prefix, 0) == 0 &&
        std::filesystem::exists(e.path() / coupling::kBundleDataFile))
      found.push_back(e.path());
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto status = icd::experiments::benchmark_preamble(
          argc, argv, "bench_coupling",
          "Google Benchmark of the coupling layer per dense vertex: rigid links, origin map, "
          "barycentric baseline, contact response."))
    return *status;
  benchmark::Initialize(&argc, argv);
  if (const auto status = icd::experiments::benchmark_leftover(argc, argv, "bench_coupling"))
    return *status;
  fixtures()["sphere3"] = std::make_unique<Fixture>(sphere_asset(3));
  fixtures()["sphere5"] = std::make_unique<Fixture>(sphere_asset(5));
  for (const char* prefix : {"bunny00", "ChineseDragon"}) {
    const std::vector<std::filesystem::path> found = find_bundles(prefix);
    if (found.empty()) std::fprintf(stderr, "bench_coupling: no %s* bundle in assets/\n", prefix);
    for (const std::filesystem::path& p : found)
      fixtures()[p.filename().string()] = std::make_unique<Fixture>(coupling::read_asset_bundle(p));
  }
  for (const auto& [name, f] : fixtures()) {
    const Fixture* fp = f.get();
    benchmark::RegisterBenchmark(("Links/reference/" + name).c_str(), BM_LinksReference, fp)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Links/evaluator/" + name).c_str(), BM_LinksEvaluator, fp)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Links/apply_wrapper/" + name).c_str(), BM_LinksApplyWrapper, fp)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Links/origin_sparse/" + name).c_str(), BM_OriginSparse, fp)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Links/barycentric/" + name).c_str(), BM_Barycentric, fp)
        ->Unit(benchmark::kMicrosecond);
  }
  benchmark::RegisterBenchmark("ContactResponse/sphere3", BM_ContactResponse,
                               fixtures()["sphere3"].get())
      ->Unit(benchmark::kMicrosecond);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
