// Benchmarks of the sphere-tree builder's innermost queries on the real
// meshes, each against a baseline measured in the same run:
//  - TriangleBvh::closest (the distance queries: 20-33 % of a build) against
//    a scan of every triangle, on points near the surface (the probes of the
//    protrusion polish and the medial axis' cell centres lie there);
//  - CoverRadius (the polish's covering radius) along a pattern-search walk
//    against the maximum over every member.
// The builder's distance queries must keep their visiting order to keep the
// trees (see experiments/spheretree/results/README.md, "This session (8)"):
// judge changes to them here, where the run-to-run spread of a whole build
// (about 10 %) does not hide them.
// Run: build/experiments/spheretree/bench_spheretree [--benchmark_repetitions=5]
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <vector>

#include "icd/config.hpp"
#include "mesh/io/surface_reader.hpp"
#include "mesh/io/triangle_geometry.hpp"
#include "mesh/spheres/protrusion.hpp"
#include "mesh/spheres/surface_sampling.hpp"
#include "mesh/spheres/triangle_bvh.hpp"

namespace {

using icd::mesh::TriangleBvh;

std::filesystem::path data_file(const char* name) {
  const char* env = std::getenv("ICD_DATA_DIR");
  return std::filesystem::path(env && *env ? env : ICD_DATA_DIR) / name;
}

/// 4096 query points: surface samples moved along a random direction by up
/// to 2 % of the longest bounding-box side.
std::vector<Eigen::Vector3d> queries_near(const icd::SurfaceMesh& mesh) {
  const double size = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).maxCoeff();
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
  const auto path = data_file(name);
  if (!std::filesystem::exists(path)) return state.SkipWithError("mesh missing");
  const icd::SurfaceMesh mesh = icd::read_surface_mesh(path);
  const TriangleBvh bvh(mesh.V, mesh.F);
  const auto queries = queries_near(mesh);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(bvh.closest(queries[i]).squared_distance);
    i = (i + 1) % queries.size();
  }
  state.SetItemsProcessed(state.iterations());
}

// Baseline: every triangle (the same closest-point routine).
void BM_Closest_ScanBaseline(benchmark::State& state, const char* name) {
  const auto path = data_file(name);
  if (!std::filesystem::exists(path)) return state.SkipWithError("mesh missing");
  const icd::SurfaceMesh mesh = icd::read_surface_mesh(path);
  const auto queries = queries_near(mesh);
  size_t i = 0;
  for (auto _ : state) {
    const Eigen::Vector3d& p = queries[i];
    double best = 1e300;
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
      const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                            c = mesh.V.row(mesh.F(f, 2));
      best = std::min(best, (icd::closest_point_on_triangle(p, a, b, c) - p).squaredNorm());
    }
    benchmark::DoNotOptimize(best);
    i = (i + 1) % queries.size();
  }
  state.SetItemsProcessed(state.iterations());
}

/// A patch of samples (those within 15 % of the size from a surface point)
/// and a walk of 400 centres around the patch's centroid in steps of 0.2 %
/// of the size, as the polish moves a leaf.
struct CoverCase {
  icd::MatX3d points;
  Eigen::VectorXd gap;
  icd::mesh::MedialSpheres medial;
  std::vector<int> members;
  std::vector<Eigen::Vector3d> walk;
  double step = 0;
};

CoverCase cover_case(const icd::SurfaceMesh& mesh) {
  CoverCase c;
  const double size = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).maxCoeff();
  const auto samples =
      icd::mesh::sample_surface(mesh.V, mesh.F, icd::mesh::SamplingOptions{0.002 * size});
  c.points = samples.points;
  c.gap = samples.gap;
  c.medial.centers = icd::MatX3d::Zero(1, 3);
  c.medial.radii = Eigen::VectorXd::Zero(1);
  c.medial.circumradii = c.medial.radii;
  const Eigen::Vector3d seed = c.points.row(0).transpose();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (Eigen::Index s = 0; s < c.points.rows(); ++s) {
    if ((c.points.row(s).transpose() - seed).norm() < 0.15 * size) {
      c.members.push_back(static_cast<int>(s));
      centroid += c.points.row(s).transpose();
    }
  }
  centroid /= static_cast<double>(c.members.size());
  c.step = 0.002 * size;
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss;
  Eigen::Vector3d x = centroid;
  for (int k = 0; k < 400; ++k) {
    c.walk.push_back(x);
    x += c.step * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  }
  return c;
}

void BM_CoverRadius_Bands(benchmark::State& state, const char* name) {
  const auto path = data_file(name);
  if (!std::filesystem::exists(path)) return state.SkipWithError("mesh missing");
  const CoverCase c = cover_case(icd::read_surface_mesh(path));
  const icd::mesh::PointGrid grid(c.medial.centers, 1.0);
  const icd::mesh::ReductionProblem problem{c.points, c.gap, c.medial, grid};
  for (auto _ : state) {
    icd::mesh::CoverRadius cover(problem, c.members, 4 * c.step);
    double sum = 0;
    for (const auto& x : c.walk) sum += cover(x);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(c.walk.size()));
  state.counters["members"] = static_cast<double>(c.members.size());
}

// Baseline: the maximum over every member at every centre.
void BM_CoverRadius_AllMembersBaseline(benchmark::State& state, const char* name) {
  const auto path = data_file(name);
  if (!std::filesystem::exists(path)) return state.SkipWithError("mesh missing");
  const CoverCase c = cover_case(icd::read_surface_mesh(path));
  const icd::mesh::PointGrid grid(c.medial.centers, 1.0);
  const icd::mesh::ReductionProblem problem{c.points, c.gap, c.medial, grid};
  for (auto _ : state) {
    double sum = 0;
    for (const auto& x : c.walk) {
      double r = 0;
      for (int s : c.members) r = std::max(r, problem.reach(s, x));
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

BENCHMARK_MAIN();
