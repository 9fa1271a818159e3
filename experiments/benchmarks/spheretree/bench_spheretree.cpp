// Benchmarks of the sphere-tree builder's innermost queries on the real
// meshes, each against a baseline measured in the same run:
//  - TriangleBvh::closest (the distance queries: 20-33 % of a build) against
//    a scan of every triangle, on points near the surface (the probes of the
//    protrusion polish and the medial axis' cell centres lie there);
//  - CoverRadius (the polish's covering radius) along a pattern-search walk
//    against the maximum over every member.
// The builder's distance queries must keep their visiting order to keep the
// trees (the build flips early greedy decisions on a last-bit change of a
// distance): judge changes to them here, where the run-to-run spread of a
// whole build (about 10 %) does not hide them. Recorded figures:
// experiments/studies/spheretree/results/README.md, "Build time".
// Run: <build>/bin/bench_spheretree [--benchmark_repetitions=5]
#include <benchmark/benchmark.h>

#include "experiments/common/benchmark_main.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <random>
#include <vector>

#include <icd/config.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/core/triangle_geometry.hpp>
#include <icd/mesh/spheres/protrusion.hpp>
#include <icd/mesh/spheres/surface_sampling.hpp>
#include <icd/mesh/spheres/triangle_bvh.hpp>

namespace {

using icd::mesh::TriangleBvh;

/// The mesh `name` of the data folder, or nothing (the benchmark marked as
/// skipped) when it is missing.
std::optional<icd::SurfaceMesh> load(benchmark::State& state, const char* name) {
  const char* env = std::getenv("ICD_DATA_DIR");
  const auto path = std::filesystem::path(env && *env ? env : ICD_DATA_DIR) / name;
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("mesh missing");
    return std::nullopt;
  }
  return icd::read_surface_mesh(path);
}

/// 4096 query points: surface samples moved along a random direction by up
/// to 2 % of the longest bounding-box side.
std::vector<Eigen::Vector3d> queries_near(const icd::SurfaceMesh& mesh) {
  const double size = icd::mesh::longest_bounding_box_side(mesh.V);
  const auto samples =
      icd::mesh::sample_surface(mesh.V, mesh.F, icd::mesh::SamplingOptions{0.01 * size});
  std::mt19937 rng(3);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<Eigen::Index> pick(0, samples.points.rows() - 1);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < 4096; ++i) {
    const Eigen::Vector3d d(gauss(rng), gauss(rng), gauss(rng));
    out.push_back(samples.points.row(pick(rng)).transpose() +
                  0.02 * size * unit(rng) * d.normalized());
  }
  return out;
}

void BM_Closest_Bvh(benchmark::State& state, const char* name) {
  const auto mesh = load(state, name);
  if (!mesh) return;
  const TriangleBvh bvh(mesh->V, mesh->F);
  const auto queries = queries_near(*mesh);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(bvh.closest(queries[i]).squared_distance);
    i = (i + 1) % queries.size();
  }
  state.SetItemsProcessed(state.iterations());
}

// Baseline: every triangle (the same closest-point routine).
void BM_Closest_ScanBaseline(benchmark::State& state, const char* name) {
  const auto mesh = load(state, name);
  if (!mesh) return;
  const auto queries = queries_near(*mesh);
  size_t i = 0;
  for (auto _ : state) {
    const Eigen::Vector3d& p = queries[i];
    double best = 1e300;
    for (Eigen::Index f = 0; f < mesh->F.rows(); ++f) {
      const Eigen::Vector3d a = mesh->V.row(mesh->F(f, 0)), b = mesh->V.row(mesh->F(f, 1)),
                            c = mesh->V.row(mesh->F(f, 2));
      best = std::min(best, (icd::closest_point_on_triangle(p, a, b, c) - p).squaredNorm());
    }
    benchmark::DoNotOptimize(best);
    i = (i + 1) % queries.size();
  }
  state.SetItemsProcessed(state.iterations());
}

/// A patch of samples (those within 15 % of the size from a surface point)
/// and a walk of 400 centres around the patch's centroid in steps of 0.2 %
/// of the size, as the polish moves a leaf; with the ReductionProblem over
/// them that CoverRadius reads (no candidate centres: one dummy).
class CoverCase {
 public:
  explicit CoverCase(const icd::SurfaceMesh& mesh)
      : m_samples(icd::mesh::sample_surface(
            mesh.V, mesh.F,
            icd::mesh::SamplingOptions{0.002 * icd::mesh::longest_bounding_box_side(mesh.V)})),
        m_medial(dummy_medial()),
        m_grid(m_medial.centers, 1.0),
        problem{m_samples.points, m_samples.gap, m_medial, m_grid} {
    const double size = icd::mesh::longest_bounding_box_side(mesh.V);
    const Eigen::Vector3d seed = m_samples.points.row(0).transpose();
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (Eigen::Index s = 0; s < m_samples.points.rows(); ++s) {
      if ((m_samples.points.row(s).transpose() - seed).norm() < 0.15 * size) {
        members.push_back(static_cast<int>(s));
        centroid += m_samples.points.row(s).transpose();
      }
    }
    centroid /= static_cast<double>(members.size());
    step = 0.002 * size;
    std::mt19937 rng(5);
    std::normal_distribution<double> gauss;
    Eigen::Vector3d x = centroid;
    for (int k = 0; k < 400; ++k) {
      walk.push_back(x);
      x += step * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    }
  }
  CoverCase(const CoverCase&) = delete;
  CoverCase& operator=(const CoverCase&) = delete;

 private:
  static icd::mesh::MedialSpheres dummy_medial() {
    icd::mesh::MedialSpheres m;
    m.centers = icd::MatX3d::Zero(1, 3);
    m.radii = Eigen::VectorXd::Zero(1);
    m.circumradii = m.radii;
    return m;
  }
  icd::mesh::SurfaceSamples m_samples;
  icd::mesh::MedialSpheres m_medial;
  icd::mesh::PointGrid m_grid;

 public:
  const icd::mesh::ReductionProblem problem;
  std::vector<int> members;
  std::vector<Eigen::Vector3d> walk;
  double step = 0;
};

void BM_CoverRadius_Bands(benchmark::State& state, const char* name) {
  const auto mesh = load(state, name);
  if (!mesh) return;
  const CoverCase c(*mesh);
  for (auto _ : state) {
    icd::mesh::CoverRadius cover(c.problem, c.members, 4 * c.step);
    double sum = 0;
    for (const auto& x : c.walk) sum += cover(x);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(c.walk.size()));
  state.counters["members"] = static_cast<double>(c.members.size());
}

// Baseline: the maximum over every member at every centre.
void BM_CoverRadius_AllMembersBaseline(benchmark::State& state, const char* name) {
  const auto mesh = load(state, name);
  if (!mesh) return;
  const CoverCase c(*mesh);
  for (auto _ : state) {
    double sum = 0;
    for (const auto& x : c.walk) {
      double r = 0;
      for (int s : c.members) r = std::max(r, c.problem.reach(s, x));
      sum += r;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(c.walk.size()));
}

}  // namespace

BENCHMARK_CAPTURE(BM_Closest_Bvh, bunny, "bunny00.off");
BENCHMARK_CAPTURE(BM_Closest_ScanBaseline, bunny, "bunny00.off");
BENCHMARK_CAPTURE(BM_Closest_Bvh, dragon, "ChineseDragon-10kv.off");
BENCHMARK_CAPTURE(BM_Closest_ScanBaseline, dragon, "ChineseDragon-10kv.off");
BENCHMARK_CAPTURE(BM_CoverRadius_Bands, dragon, "ChineseDragon-10kv.off");
BENCHMARK_CAPTURE(BM_CoverRadius_AllMembersBaseline, dragon, "ChineseDragon-10kv.off");

ICD_BENCHMARK_MAIN("bench_spheretree",
                   "Google Benchmark of the sphere-tree builder's distance queries and covering radius against brute force.");
