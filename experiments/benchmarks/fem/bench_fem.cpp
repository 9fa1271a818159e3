// Google Benchmark of the FEM kernels: internal-force evaluation per material
// and one step per integrator, on ~1k, ~4k and ~30k-tet structured bars and
// on the coarse tet meshes of the pipeline's asset bundles (bunny, dragon;
// nodes reordered by reverse Cuthill-McKee), plus the force evaluation with
// the fused health check, with the fused orientation test only, the separate
// health pass and the force differential
// (the Lanczos product) on the ~4k-tet bar.
// Reported as time per tet (counter "per_tet", seconds; shown with an SI
// prefix, e.g. 30n = 30 ns/tet). Single thread unless the name says threads:2.
#include <benchmark/benchmark.h>

#include "experiments/common/benchmark_main.hpp"

#include <algorithm>
#include <filesystem>
#include <numeric>
#include <random>
#include <string>

#include <icd/fem/backward_euler.hpp>
#include <icd/fem/lane_loops.hpp>
#include <icd/fem/reorder.hpp>
#include <icd/fem/simulator.hpp>
#include <icd/fem/stable_step.hpp>
#include <icd/config.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/vtu_reader.hpp>

namespace {

using namespace icd;
using namespace icd::fem;

// Bars 1 x 0.1 x 0.1 m scaled to keep near-cubic cells: r = 1.5, 2, 4 ->
// 20x3x3 = 1080, 40x4x4 = 3840, 80x8x8 = 30720 tets.
TetMesh bar(int level) {
  BoxMeshOptions o;
  const int n[3][3] = {{20, 3, 3}, {40, 4, 4}, {80, 8, 8}};
  o.nx = n[level][0];
  o.ny = n[level][1];
  o.nz = n[level][2];
  return make_box_tet_mesh(o);
}

Material material(int model) {
  Material m;
  m.model = static_cast<MaterialModel>(model);
  m.young = 1e6;
  m.poisson = 0.3;
  return m;
}

void set_per_tet(benchmark::State& state, long tets, double evaluations_per_iteration = 1) {
  state.counters["per_tet"] = benchmark::Counter(
      static_cast<double>(tets) * evaluations_per_iteration,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["tets"] = static_cast<double>(tets);
}

// Args: model, mesh level, threads.
void BM_Forces(benchmark::State& state) {
  const TetMesh m = bar(static_cast<int>(state.range(1)));
  ForceOptions fo;
  fo.num_threads = static_cast<int>(state.range(2));
  ElasticForces forces(make_tet_mesh_data(m.V, m.T), material(static_cast<int>(state.range(0))),
                       fo);
  // A mildly deformed state (so corotational needs real polar iterations).
  MatX3d x = m.V;
  for (int i = 0; i < x.rows(); ++i)
    x(i, 2) += 0.05 * x(i, 0) * x(i, 0) + 0.001 * std::sin(37.0 * i);
  MatX3d f(x.rows(), 3);
  for (auto _ : state) {
    forces.compute(x, f);
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
  state.SetLabel(to_string(forces.material().model));
  set_per_tet(state, m.T.rows());
}

// Args: integrator, mesh level. StVK, E = 1e6, gravity, clamped end, alpha = 1.
void BM_Step(benchmark::State& state) {
  const auto integ = static_cast<Integrator>(state.range(0));
  const TetMesh m = bar(static_cast<int>(state.range(1)));
  ModelOptions mo;
  mo.gravity = {0, 0, -9.81};
  mo.damping = {1.0, 0.0};
  Model model(m.V, m.T, material(static_cast<int>(MaterialModel::StVK)), mo);
  std::vector<int> fixed;
  for (int i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) < 1e-12) fixed.push_back(i);
  model.set_fixed_nodes(fixed);
  State s{m.V, MatX3d::Zero(m.V.rows(), 3)};
  const double omega = estimate_max_frequency(model, s.x, {}).omega_max;
  const double h = integ == Integrator::BackwardEuler
                       ? 1.0 / 60
                       : 0.9 * stable_step_limit(integ, omega, model.damping());
  ExplicitStepper ex;
  BackwardEulerStepper be;
  for (auto _ : state) {
    switch (integ) {
      case Integrator::RK4:
        ex.rk4(model, s, h);
        break;
      case Integrator::SymplecticEuler:
        ex.symplectic_euler(model, s, h);
        break;
      case Integrator::BackwardEuler:
        be.step(model, s, h);
        break;
    }
    benchmark::DoNotOptimize(s.x.data());
  }
  state.SetLabel(to_string(integ));
  set_per_tet(state, m.T.rows());
  state.counters["step_s"] = h;
}

// Memory locality: the 30,720-tet bar (StVK) in generator order (0), with
// nodes and elements randomly shuffled (1), and shuffled then reordered by
// reverse Cuthill-McKee (2), as a mesh from the pipeline would be.
void BM_ForcesOrdering(benchmark::State& state) {
  TetMesh m = bar(2);
  if (state.range(0) >= 1) {
    std::vector<int> perm(m.V.rows()), eperm(m.T.rows());
    std::iota(perm.begin(), perm.end(), 0);
    std::iota(eperm.begin(), eperm.end(), 0);
    std::mt19937 gen(0);
    std::shuffle(perm.begin(), perm.end(), gen);
    std::shuffle(eperm.begin(), eperm.end(), gen);
    TetMesh s;
    s.V.resize(m.V.rows(), 3);
    for (int i = 0; i < m.V.rows(); ++i) s.V.row(perm[i]) = m.V.row(i);
    s.T.resize(m.T.rows(), 4);
    for (int e = 0; e < m.T.rows(); ++e)
      for (int a = 0; a < 4; ++a) s.T(eperm[e], a) = perm[m.T(e, a)];
    m = s;
  }
  if (state.range(0) == 2) {
    const ReorderedMesh r = reorder_for_locality(m.V, m.T);
    m.V = r.V;
    m.T = r.T;
  }
  ElasticForces forces(make_tet_mesh_data(m.V, m.T),
                       material(static_cast<int>(MaterialModel::StVK)));
  MatX3d x = m.V;
  for (int i = 0; i < x.rows(); ++i) x(i, 2) += 0.05 * x(i, 0) * x(i, 0);
  MatX3d f(x.rows(), 3);
  for (auto _ : state) {
    forces.compute(x, f);
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
  state.SetLabel(state.range(0) == 0   ? "generator order"
                 : state.range(0) == 1 ? "shuffled"
                                       : "shuffled + RCM");
  set_per_tet(state, m.T.rows());
  state.counters["bandwidth"] = node_bandwidth(m.T);
}
BENCHMARK(BM_ForcesOrdering)->DenseRange(0, 2)->ArgName("order")->MinTime(0.2);

// The coarse tet mesh of the asset bundle whose folder name starts with
// `prefix` under <source>/assets (written by icd-preprocess); empty if none.
TetMesh asset_coarse_mesh(const std::string& prefix) {
  const std::filesystem::path dir = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const auto file = entry.path() / "coarse_tets.vtu";
    if (name.rfind(prefix, 0) == 0 && std::filesystem::exists(file)) return read_vtu_tet_mesh(file);
  }
  return {};
}

// Args: model, asset (0 bunny, 1 dragon). A mildly deformed state as BM_Forces.
void BM_ForcesAsset(benchmark::State& state) {
  const char* prefix = state.range(1) == 0 ? "bunny00-" : "ChineseDragon-10kv-";
  const TetMesh raw = asset_coarse_mesh(prefix);
  if (raw.T.rows() == 0) {
    state.SkipWithError("no coarse_tets.vtu under assets/ (run icd-preprocess)");
    return;
  }
  const ReorderedMesh m = reorder_for_locality(raw.V, raw.T);
  ElasticForces forces(make_tet_mesh_data(m.V, m.T), material(static_cast<int>(state.range(0))));
  const double size = (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).maxCoeff();
  MatX3d x = m.V;
  for (int i = 0; i < x.rows(); ++i)
    x(i, 2) += 0.05 * x(i, 0) * x(i, 0) / size + 0.001 * size * std::sin(37.0 * i);
  MatX3d f(x.rows(), 3);
  for (auto _ : state) {
    forces.compute(x, f);
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
  state.SetLabel(std::string(prefix) + " " + to_string(forces.material().model));
  set_per_tet(state, m.T.rows());
  state.counters["bandwidth"] = node_bandwidth(m.T);
}
BENCHMARK(BM_ForcesAsset)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1}})
    ->ArgNames({"model", "asset"})
    ->MinTime(0.2);

// Args: kind (0 compute, 1 compute_with_health, 2 health, 3 differential, 4
// compute_with_orientation_check), model; the ~4k-tet bar.
void BM_Kernels(benchmark::State& state) {
  const int kind = static_cast<int>(state.range(0));
  // isa 1: the lane loops' AVX2 build (the default where the CPU has it), 0: baseline x86-64.
  const lanes::LaneIsa isa = state.range(2) == 1 ? lanes::LaneIsa::AVX2 : lanes::LaneIsa::Baseline;
  const lanes::LaneIsa before = lanes::lane_isa();
  if (!lanes::set_lane_isa(isa)) {
    state.SkipWithError("the CPU lacks AVX2");
    return;
  }
  const TetMesh m = bar(1);
  ElasticForces forces(make_tet_mesh_data(m.V, m.T), material(static_cast<int>(state.range(1))));
  MatX3d x = m.V;
  for (int i = 0; i < x.rows(); ++i)
    x(i, 2) += 0.05 * x(i, 0) * x(i, 0) + 0.001 * std::sin(37.0 * i);
  const MatX3d dx = MatX3d::Constant(x.rows(), 3, 1e-3);
  MatX3d f(x.rows(), 3);
  for (auto _ : state) {
    switch (kind) {
      case 0:
        forces.compute(x, f);
        break;
      case 1:
        benchmark::DoNotOptimize(forces.compute_with_health(x, f));
        break;
      case 2:
        benchmark::DoNotOptimize(forces.health(x));
        break;
      case 3:
        forces.differential(x, dx, f);
        break;
      case 4:
        benchmark::DoNotOptimize(forces.compute_with_orientation_check(x, f));
        break;
    }
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
  const char* names[5] = {"forces", "forces + health", "health", "differential",
                          "forces + orientation"};
  state.SetLabel(std::string(names[kind]) + " " + to_string(forces.material().model) + " " +
                 lanes::to_string(isa));
  lanes::set_lane_isa(before);
  set_per_tet(state, m.T.rows());
}
BENCHMARK(BM_Kernels)
    ->ArgsProduct({{0, 1, 2, 3, 4}, {0, 1, 2, 3}, {0, 1}})
    ->ArgNames({"kind", "model", "isa"})
    ->MinTime(0.2);

// Single thread: rates from CPU time (robust on a shared machine).
BENCHMARK(BM_Forces)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1, 2}, {1}})
    ->ArgNames({"model", "mesh", "threads"})
    ->MinTime(0.2);
// Two threads: rates from wall time (CPU time would count one thread only).
BENCHMARK(BM_Forces)
    ->ArgsProduct({{0, 1, 2, 3}, {2}, {2}})
    ->ArgNames({"model", "mesh", "threads"})
    ->MinTime(0.2)
    ->UseRealTime();
BENCHMARK(BM_Step)
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2}})
    ->ArgNames({"integrator", "mesh"})
    ->MinTime(0.2);

}  // namespace

ICD_BENCHMARK_MAIN("bench_fem",
                   "Google Benchmark of the FEM kernels: force evaluation per material, one step per integrator.");
