// The real-time claim of issue 3: a 3,840-tet object, E = 1e6 Pa, nu = 0.3,
// clamped at x = 0, gravity: either the 40 x 4 x 4-cell bar 1.0 x 0.1 x 0.1 m
// (0.025 m cells) or a 10 x 8 x 8-cell block 1.0 x 0.8 x 0.8 m (0.1 m cells);
// StVK (the paper's model), advanced frame by frame (1/60 s) by the
// Simulator with automatic steps (0.9 x the stable limit, re-estimated each
// frame, health checks on). Prints wall time per simulated second for RK4
// and symplectic Euler, each the median of 5 repetitions of 1 simulated second,
// and the process CPU time (the honest number on a shared, loaded machine).
//
// Usage: fem_realtime [bar|block] [threads]
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fem/simulator.hpp"
#include "mesh/io/primitives.hpp"

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
  std::printf("%s mesh: %ld tets, %ld nodes, %d thread(s)\n", block ? "block" : "bar", static_cast<long>(m.T.rows()),
              static_cast<long>(m.V.rows()), threads);
  double wall_per_sim[2] = {0, 0}, cpu_per_sim[2] = {0, 0};
  const Integrator integs[2] = {Integrator::RK4, Integrator::SymplecticEuler};
  for (int k = 0; k < 2; ++k) {
    std::vector<double> walls, cpus;
    AdvanceReport last;
    for (int rep = 0; rep < 5; ++rep) {
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
      so.integrator = integs[k];
      Simulator sim(std::move(model), so);
      const auto t0 = std::chrono::steady_clock::now();
      const std::clock_t c0 = std::clock();
      for (int f = 0; f < 60; ++f) last = sim.advance(1.0 / 60);
      cpus.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
      walls.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(walls.begin(), walls.end());
    std::sort(cpus.begin(), cpus.end());
    wall_per_sim[k] = walls[2];
    std::printf("%-17s step %.3e s (limit %.3e s, omega_max %.0f rad/s), %d substeps/frame: "
                "per simulated second: wall %.3f s (median of 5; min %.3f), process CPU %.3f s -> %.2fx real "
                "time by wall, %.2fx by CPU\n",
                to_string(integs[k]), last.step, last.step_limit, last.omega_max, last.substeps, walls[2],
                walls[0], cpus[2], 1.0 / walls[2], 1.0 / cpus[2]);
    cpu_per_sim[k] = cpus[2];
  }
  std::printf("symplectic Euler is %.2fx faster than RK4 by wall time, %.2fx by CPU time\n",
              wall_per_sim[0] / wall_per_sim[1], cpu_per_sim[0] / cpu_per_sim[1]);
  return 0;
}
