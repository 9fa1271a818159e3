// The real-time claim of issue 3: a 3,840-tet object, E = 1e6 Pa, nu = 0.3,
// clamped at x = 0, gravity: either the 40 x 4 x 4-cell bar 1.0 x 0.1 x 0.1 m
// (0.025 m cells) or a 10 x 8 x 8-cell block 1.0 x 0.8 x 0.8 m (0.1 m cells);
// StVK (the paper's model), advanced frame by frame (1/60 s) by the
// Simulator with automatic steps (0.9 x the stable limit, re-estimated each
// frame, health checks on). Prints, for RK4 and symplectic Euler, the process
// CPU time and the wall time per simulated second (medians of 7 repetitions
// of 1 simulated second, a fresh Simulator each), their ratios, and the cost
// of the health checks: every step (the default), every 4th step, and only
// at the end of each frame. The load average is printed
// before and after: the machine may be shared.
//
// Usage: fem_realtime [bar|block] [threads]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "fem/simulator.hpp"
#include "mesh/io/primitives.hpp"

namespace {

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return in ? a + " " + b + " " + c : "unknown";
}

struct Run {
  double wall = 0, cpu = 0;
  icd::fem::AdvanceReport last;
  long force_evaluations = 0;  // in the simulated second, from the sub-step counts
};

// One simulated second (60 frames) with a fresh Simulator.
Run run_once(const icd::TetMesh& m, icd::fem::Integrator integ, int check_interval, int threads) {
  using namespace icd::fem;
  Material mat;
  mat.model = MaterialModel::StVK;
  mat.young = 1e6;
  ModelOptions mo;
  mo.gravity = {0, 0, -9.81};
  mo.damping = {1.0, 0.0};
  mo.forces.num_threads = threads;
  Model model(m.V, m.T, mat, mo);
  std::vector<int> fixed;
  for (int i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) < 1e-12) fixed.push_back(i);
  model.set_fixed_nodes(fixed);
  SimulatorOptions so;
  so.integrator = integ;
  so.check_interval = check_interval;
  Simulator sim(std::move(model), so);
  Run r;
  long substeps = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  for (int f = 0; f < 60; ++f) {
    r.last = sim.advance(1.0 / 60);
    substeps += r.last.substeps;
  }
  r.cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.force_evaluations = substeps * (integ == Integrator::RK4 ? 4 : 1);
  return r;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  using namespace icd;
  using namespace icd::fem;
  const bool block = argc > 1 && std::string(argv[1]) == "block";
  const int threads = argc > 2 ? std::atoi(argv[2]) : 1;
  BoxMeshOptions bo;
  bo.nx = block ? 10 : 40;
  bo.ny = block ? 8 : 4;
  bo.nz = block ? 8 : 4;
  bo.size = block ? Eigen::Vector3d(1.0, 0.8, 0.8) : Eigen::Vector3d(1.0, 0.1, 0.1);
  const TetMesh m = make_box_tet_mesh(bo);
  std::printf("%s mesh: %ld tets, %ld nodes, %d thread(s); load average before: %s\n", block ? "block" : "bar",
              static_cast<long>(m.T.rows()), static_cast<long>(m.V.rows()), threads, load_average().c_str());
  // Six configurations (2 integrators x checks every step / every 4th step /
  // at frame ends only), interleaved repetition by repetition so that load
  // changes on a shared machine hit all of them alike; medians of 7.
  const Integrator integs[2] = {Integrator::RK4, Integrator::SymplecticEuler};
  const int intervals[3] = {1, 4, 1 << 30};
  const int reps = 7;
  std::vector<double> cpu[2][3], wall[2][3];
  Run last[2];
  for (int rep = 0; rep < reps; ++rep)
    for (int k = 0; k < 2; ++k)
      for (int c = 0; c < 3; ++c) {
        const Run r = run_once(m, integs[k], intervals[c], threads);
        cpu[k][c].push_back(r.cpu);
        wall[k][c].push_back(r.wall);
        if (c == 0) last[k] = r;
      }
  double cpu_med[2], wall_med[2];
  for (int k = 0; k < 2; ++k) {
    cpu_med[k] = median(cpu[k][0]);
    wall_med[k] = median(wall[k][0]);
    const Run& t = last[k];
    std::printf("%-17s last frame: step %.3e s (limit %.3e s, omega bound %.0f rad/s), %d substeps; %ld force "
                "evaluations per simulated second: process CPU %.3f s, wall %.3f s (medians of %d) -> %.2fx real "
                "time by CPU, %.2fx by wall; %.0f ns CPU per tet and force evaluation\n",
                to_string(integs[k]), t.last.step, t.last.step_limit, t.last.omega_max, t.last.substeps,
                t.force_evaluations, cpu_med[k], wall_med[k], reps, 1.0 / cpu_med[k], 1.0 / wall_med[k],
                cpu_med[k] / t.force_evaluations / m.T.rows() * 1e9);
  }
  std::printf("symplectic Euler is %.2fx faster than RK4 by CPU time, %.2fx by wall time (4 evaluations vs 1 "
              "at limits 2.83/omega vs 2/omega: 2.83x)\n",
              cpu_med[0] / cpu_med[1], wall_med[0] / wall_med[1]);
  for (int k = 0; k < 2; ++k) {
    const double every = cpu_med[k], every4 = median(cpu[k][1]), end = median(cpu[k][2]);
    std::printf("%-17s health checks every step / every 4th step / at frame ends only: CPU %.3f / %.3f / %.3f s "
                "per simulated s: every step %+.1f%%, every 4th %+.1f%% vs frame ends only\n",
                to_string(integs[k]), every, every4, end, 100 * (every / end - 1), 100 * (every4 / end - 1));
  }
  std::printf("load average after: %s\n", load_average().c_str());
  return 0;
}
