// Benchmarks of the mesh readers on the real meshes, each against a baseline
// measured in the same run: a straightforward iostream OFF parser (operator>>).
// Run: <build>/bin/bench_mesh_io [--benchmark_repetitions=5]
#include <benchmark/benchmark.h>

#include "experiments/common/benchmark_main.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <icd/config.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/vtk_writer.hpp>
#include <icd/mesh/io/vtu_reader.hpp>

namespace {

std::filesystem::path data_file(const char* name) {
  const char* env = std::getenv("ICD_DATA_DIR");
  return std::filesystem::path(env && *env ? env : ICD_DATA_DIR) / name;
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Baseline: the usual iostream OFF reader (no validation beyond stream state).
icd::SurfaceMesh iostream_off(const std::string& text) {
  std::istringstream in(text);
  std::string header;
  int nv = 0, nf = 0, ne = 0;
  in >> header >> nv >> nf >> ne;
  icd::SurfaceMesh m;
  m.V.resize(nv, 3);
  m.F.resize(nf, 3);
  for (int i = 0; i < nv; ++i) in >> m.V(i, 0) >> m.V(i, 1) >> m.V(i, 2);
  for (int f = 0; f < nf; ++f) {
    int n = 0;
    in >> n >> m.F(f, 0) >> m.F(f, 1) >> m.F(f, 2);
  }
  if (!in) std::abort();
  return m;
}

void BM_ParseOff_Ours(benchmark::State& state, const char* name) {
  const auto path = data_file(name);
  if (!std::filesystem::exists(path)) return state.SkipWithError("mesh missing");
  const std::string text = slurp(path);
  for (auto _ : state) benchmark::DoNotOptimize(icd::parse_off(text, name).F.data());
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * text.size()));
}

void BM_ParseOff_IostreamBaseline(benchmark::State& state, const char* name) {
  const auto path = data_file(name);
  if (!std::filesystem::exists(path)) return state.SkipWithError("mesh missing");
  const std::string text = slurp(path);
  for (auto _ : state) benchmark::DoNotOptimize(iostream_off(text).F.data());
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * text.size()));
}

// End to end from disk (page cache warm), what read_surface_mesh costs a caller.
void BM_ReadSurfaceMesh_FromFile(benchmark::State& state, const char* name) {
  const auto path = data_file(name);
  if (!std::filesystem::exists(path)) return state.SkipWithError("mesh missing");
  for (auto _ : state) benchmark::DoNotOptimize(icd::read_surface_mesh(path).F.data());
}

void BM_VtuWriteRead(benchmark::State& state) {
  const auto path = data_file("bunny00.off");
  if (!std::filesystem::exists(path)) return state.SkipWithError("mesh missing");
  const icd::SurfaceMesh m = icd::read_surface_mesh(path);
  const auto out = std::filesystem::temp_directory_path() / "icd_bench_mesh_io.vtu";
  for (auto _ : state) {
    icd::write_vtu_surface_mesh(out, m);
    benchmark::DoNotOptimize(icd::read_vtu_surface_mesh(out).F.data());
  }
  std::filesystem::remove(out);
}

// Baseline for boundary_faces: the first implementation, counting faces in a
// std::map (the library now sorts face records).
icd::MatX3i boundary_faces_map(const icd::MatX4i& T) {
  static constexpr int faces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::map<std::array<int, 3>, int> count;
  for (int e = 0; e < T.rows(); ++e)
    for (const auto& f : faces) {
      std::array<int, 3> key{T(e, f[0]), T(e, f[1]), T(e, f[2])};
      std::sort(key.begin(), key.end());
      ++count[key];
    }
  std::vector<std::array<int, 3>> out;
  for (int e = 0; e < T.rows(); ++e)
    for (const auto& f : faces) {
      std::array<int, 3> key{T(e, f[0]), T(e, f[1]), T(e, f[2])};
      std::sort(key.begin(), key.end());
      if (count[key] == 1) out.push_back({T(e, f[0]), T(e, f[1]), T(e, f[2])});
    }
  icd::MatX3i F(static_cast<Eigen::Index>(out.size()), 3);
  for (size_t i = 0; i < out.size(); ++i) F.row(i) << out[i][0], out[i][1], out[i][2];
  return F;
}

icd::TetMesh bench_box() {
  icd::BoxMeshOptions o;
  o.nx = 25;
  o.ny = 20;
  o.nz = 20;  // 60,000 tets
  return icd::make_box_tet_mesh(o);
}

void BM_BoundaryFaces_Sorted(benchmark::State& state) {
  const icd::TetMesh m = bench_box();
  for (auto _ : state) benchmark::DoNotOptimize(icd::boundary_faces(m.T).data());
}

void BM_BoundaryFaces_MapBaseline(benchmark::State& state) {
  const icd::TetMesh m = bench_box();
  if (boundary_faces_map(m.T) != icd::boundary_faces(m.T)) return state.SkipWithError("differ");
  for (auto _ : state) benchmark::DoNotOptimize(boundary_faces_map(m.T).data());
}

BENCHMARK_CAPTURE(BM_ParseOff_Ours, bunny, "bunny00.off")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ParseOff_IostreamBaseline, bunny, "bunny00.off")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadSurfaceMesh_FromFile, bunny, "bunny00.off")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ParseOff_Ours, dragon, "ChineseDragon-10kv.off")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ParseOff_IostreamBaseline, dragon, "ChineseDragon-10kv.off")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VtuWriteRead)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BoundaryFaces_Sorted)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BoundaryFaces_MapBaseline)->Unit(benchmark::kMillisecond);

}  // namespace

ICD_BENCHMARK_MAIN("bench_mesh_io",
                   "Google Benchmark of the mesh readers on the real meshes against an iostream OFF baseline.");
