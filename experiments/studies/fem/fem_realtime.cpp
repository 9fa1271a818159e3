// The real-time claim of issue 3: a 3,840-tet object, E = 1e6 Pa, nu = 0.3,
// clamped at x = 0, gravity: either the 40 x 4 x 4-cell bar 1.0 x 0.1 x 0.1 m
// (0.025 m cells) or a 10 x 8 x 8-cell block 1.0 x 0.8 x 0.8 m (0.1 m cells);
// StVK (the paper's model), advanced frame by frame (1/60 s) by the
// Simulator with automatic steps (0.9 x the stable limit, re-estimated each
// frame, health checks on). For RK4 and symplectic Euler it measures the
// process CPU time and the wall time per simulated second (11 repetitions of
// 1 simulated second, a fresh Simulator each; per frame the median over the
// repetitions, summed over the 60 frames; the ratios also from the smallest
// per-second totals, which interference from other processes inflates least) of:
//   - the default configuration (health checks every step, lane loops in
//     the best instruction set the CPU has: AVX2 on x86-64 where present);
//   - health checks every 2nd and every 4th step, and only at the end of
//     each frame (the same check cadence for both integrators: the pure
//     integrator ratio);
//   - the default configuration with exact (force-differential) Lanczos
//     products in the per-frame re-estimates instead of forward differences,
//     with the baseline x86-64 lane loops instead of AVX2, and with both;
//   - checks every step with EnergyCheck::Full (the elastic energy and the
//     smallest det F summed in every check) instead of the default Auto
//     (for StVK: EnergyCheck::Bound, det F > 0 and a kinetic + load bound).
// All configurations are interleaved frame by frame (one Simulator each, a
// frame of each in turn), so that load changes on a shared machine hit all
// of them alike. Then it splits the
// default configuration's CPU time into force evaluations (with the health
// check fused into one of them per step; the first step of a frame reuses the
// forces of the frame-end check before it), the omega_max estimates (the cold
// first one with force differentials, the warm per-frame ones with a force
// evaluation per product, f(x) reused from the frame-end check) and the rest
// (node passes, step control, the in-situ slowdown of the kernels), from the cost of one force
// evaluation and one force differential measured in the same run. The load average is printed
// before and after: the machine may be shared.
//
// Usage: fem_realtime [bar|block] [threads]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/common/timing.hpp"
#include "experiments/studies/fem/clamped_bar.hpp"
#include <icd/fem/lane_loops.hpp>
#include <icd/fem/simulator.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace {

using namespace icd;
using namespace icd::fem;
using icd::experiments::cpu_seconds;
using icd::experiments::load_average;
using icd::experiments::median;

struct Run {
  double wall = 0, cpu = 0;
  AdvanceReport last;
  long substeps = 0;
  long first_products = 0, products = 0;  // Lanczos products: first (cold) estimate, later frames
};

std::unique_ptr<Simulator> make_simulator(const TetMesh& m, Integrator integ, int check_interval,
                                          bool fd_products, EnergyCheck energy, int threads) {
  SimulatorOptions so;
  so.integrator = integ;
  so.check_interval = check_interval;
  so.energy_check = energy;
  so.frequency_refresh_finite_differences = fd_products;
  return std::make_unique<Simulator>(clamped_stvk_model(m, threads), so);
}

// CPU seconds of one call of op (median of 3 batches of 100 calls).
template <class Op>
double cpu_per_call(Op&& op) {
  std::vector<double> t;
  for (int b = 0; b < 3; ++b) {
    const double c0 = cpu_seconds();
    for (int k = 0; k < 100; ++k) op();
    t.push_back((cpu_seconds() - c0) / 100);
  }
  return median(t);
}

int run(int argc, char** argv) {
  using icd::experiments::Cli;
  bool block = false;
  int threads = 1;
  Cli cli("fem_realtime", "  Prints the table (about 2 min for the bar).");
  cli.argument("MESH", "bar (40 x 4 x 4 cells, default) or block (10 x 8 x 8)", false,
               [&block](const std::string& v) {
                 if (v != "bar" && v != "block")
                   throw std::invalid_argument("must be bar or block, got '" + v + "'");
                 block = v == "block";
               })
      .argument("THREADS", "threads of the force evaluation (default 1)", false,
                [&threads](const std::string& v) {
                  threads = Cli::parse_integer<int>(v, 1, 256);
                });
  if (const auto status = cli.parse(argc, argv)) return *status;
  BoxMeshOptions bo;
  bo.nx = block ? 10 : 40;
  bo.ny = block ? 8 : 4;
  bo.nz = block ? 8 : 4;
  bo.size = block ? Eigen::Vector3d(1.0, 0.8, 0.8) : Eigen::Vector3d(1.0, 0.1, 0.1);
  const TetMesh m = make_box_tet_mesh(bo);
  const lanes::LaneIsa best = lanes::lane_isa();
  std::printf(
      "%s mesh: %ld tets, %ld nodes, %d thread(s), lane loops: %s; load average before: %s\n",
      block ? "block" : "bar", static_cast<long>(m.T.rows()), static_cast<long>(m.V.rows()),
      threads, lanes::to_string(best), load_average().c_str());
  struct Config {
    int check_interval;
    bool fd_products;
    lanes::LaneIsa isa;
    EnergyCheck energy;
    const char* name;
  };
  const EnergyCheck autom = EnergyCheck::Auto;
  const lanes::LaneIsa base = lanes::LaneIsa::Baseline;
  const Config configs[] = {
      {1, true, best, autom, "checks every step (default)"},
      {2, true, best, autom, "checks every 2nd step"},
      {4, true, best, autom, "checks every 4th step"},
      {1 << 30, true, best, autom, "checks at frame ends only"},
      {1, false, best, autom,
       "checks every step, exact Lanczos products (force differentials) in the re-estimates"},
      {1, true, base, autom, "checks every step, baseline x86-64 lane loops"},
      {1, false, base, autom, "checks every step, baseline lane loops and exact products"},
      {1, true, best, EnergyCheck::Full,
       "checks every step, EnergyCheck::Full (elastic energy and smallest det F summed in every "
       "check)"}};
  const int nconfigs = sizeof(configs) / sizeof(configs[0]);
  const Integrator integs[2] = {Integrator::RK4, Integrator::SymplecticEuler};
  // Unit costs: one force evaluation with and without the fused health
  // check, and one force differential, at a sagged state; measured once per
  // repetition (interleaved with the runs) with the best lane loops.
  Simulator sagged(clamped_stvk_model(m, threads));
  for (int f = 0; f < 30; ++f) sagged.advance(1.0 / 60);
  const MatX3d x = sagged.positions();
  const MatX3d dx = MatX3d::Constant(x.rows(), 3, 1e-3);
  MatX3d out(x.rows(), 3);
  ElasticForces& forces = sagged.model().elastic();
  const int reps = 11;
  std::vector<double> cpu[2][nconfigs], wall[2][nconfigs], u_eval, u_health, u_orient, u_product;
  Run last[2][nconfigs];
  // Per configuration and frame, the CPU and wall time of each repetition.
  std::vector<std::vector<double>> frame_cpu[2][nconfigs], frame_wall[2][nconfigs];
  for (int k = 0; k < 2; ++k)
    for (int c = 0; c < nconfigs; ++c) {
      frame_cpu[k][c].assign(60, {});
      frame_wall[k][c].assign(60, {});
    }
  for (int rep = 0; rep < reps; ++rep) {
    // A fresh Simulator per configuration; they advance frame by frame in
    // turn, so that load changes on the shared machine hit all alike.
    std::vector<std::unique_ptr<Simulator>> sims;
    for (int k = 0; k < 2; ++k)
      for (int c = 0; c < nconfigs; ++c)
        sims.push_back(make_simulator(m, integs[k], configs[c].check_interval,
                                      configs[c].fd_products, configs[c].energy, threads));
    Run run[2][nconfigs];
    for (int f = 0; f < 60; ++f)
      for (int k = 0; k < 2; ++k)
        for (int c = 0; c < nconfigs; ++c) {
          lanes::set_lane_isa(configs[c].isa);
          Run& r = run[k][c];
          const auto t0 = std::chrono::steady_clock::now();
          const double c0 = cpu_seconds();
          r.last = sims[k * nconfigs + c]->advance(1.0 / 60);
          const double dc = cpu_seconds() - c0;
          const double dw =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          r.cpu += dc;
          r.wall += dw;
          frame_cpu[k][c][f].push_back(dc);
          frame_wall[k][c][f].push_back(dw);
          r.substeps += r.last.substeps;
          (f == 0 ? r.first_products : r.products) += r.last.frequency_products;
        }
    for (int k = 0; k < 2; ++k)
      for (int c = 0; c < nconfigs; ++c) {
        cpu[k][c].push_back(run[k][c].cpu);
        wall[k][c].push_back(run[k][c].wall);
        last[k][c] = run[k][c];
      }
    lanes::set_lane_isa(best);
    u_eval.push_back(cpu_per_call([&] { forces.compute(x, out); }));
    u_health.push_back(cpu_per_call([&] { forces.compute_with_health(x, out); }));
    u_orient.push_back(cpu_per_call([&] { forces.compute_with_orientation_check(x, out); }));
    u_product.push_back(cpu_per_call([&] { forces.differential(x, dx, out); }));
  }
  const double t_eval = median(u_eval), t_health = median(u_health), t_orient = median(u_orient),
               t_product = median(u_product);
  const double ntets = static_cast<double>(m.T.rows());
  std::printf(
      "unit CPU costs (medians over the repetitions of 3 x 100 calls): force evaluation %.1f "
      "ns/tet, with the fused health check %.1f ns/tet, with the orientation check only %.1f "
      "ns/tet, "
      "force differential %.1f ns/tet\n",
      t_eval / ntets * 1e9, t_health / ntets * 1e9, t_orient / ntets * 1e9,
      t_product / ntets * 1e9);
  // Per simulated second: the sum over the 60 frames of each frame's median
  // over the repetitions; and the smallest per-second total of a repetition.
  double cpu_med[2][nconfigs], wall_med[2][nconfigs], cpu_min[2][nconfigs];
  for (int k = 0; k < 2; ++k)
    for (int c = 0; c < nconfigs; ++c) {
      cpu_med[k][c] = wall_med[k][c] = 0;
      for (int f = 0; f < 60; ++f) {
        cpu_med[k][c] += median(frame_cpu[k][c][f]);
        wall_med[k][c] += median(frame_wall[k][c][f]);
      }
      cpu_min[k][c] = *std::min_element(cpu[k][c].begin(), cpu[k][c].end());
    }
  for (int c = 0; c < nconfigs; ++c) {
    std::printf("%s:\n", configs[c].name);
    for (int k = 0; k < 2; ++k) {
      const Run& t = last[k][c];
      const long evals = t.substeps * (integs[k] == Integrator::RK4 ? 4 : 1);
      std::printf(
          "  %-17s last frame: step %.3e s (limit %.3e s, omega bound %.0f rad/s), %d substeps; "
          "%ld force evaluations per simulated second: process CPU %.3f s, wall %.3f s (frame "
          "medians of "
          "%d) -> %.2fx real time by CPU, %.2fx by wall; %.1f ns CPU per tet and force "
          "evaluation\n",
          to_string(integs[k]), t.last.step, t.last.step_limit, t.last.omega_max, t.last.substeps,
          evals, cpu_med[k][c], wall_med[k][c], reps, 1.0 / cpu_med[k][c], 1.0 / wall_med[k][c],
          cpu_med[k][c] / evals / ntets * 1e9);
    }
    std::printf(
        "  symplectic Euler is %.2fx faster than RK4 by CPU time (%.2fx from the minima), %.2fx by "
        "wall time (4 evaluations vs 1 at limits 2.83/omega vs 2/omega: 2.83x)\n",
        cpu_med[0][c] / cpu_med[1][c], cpu_min[0][c] / cpu_min[1][c],
        wall_med[0][c] / wall_med[1][c]);
  }
  std::printf(
      "same check cadence: RK4 checked every step (%ld checks per simulated s) vs symplectic Euler "
      "every 2nd step (%ld): %.2fx by CPU\n",
      last[0][0].substeps, (last[1][1].substeps + 1) / 2, cpu_med[0][0] / cpu_med[1][1]);
  {
    // Frames 1..59 scaled to a second: without the first frame, whose cold
    // omega_max estimate (~50 exact products) a long run pays only once.
    double steady[2][nconfigs];
    for (int k = 0; k < 2; ++k)
      for (int c = 0; c < nconfigs; ++c) {
        steady[k][c] = 0;
        for (int f = 1; f < 60; ++f) steady[k][c] += median(frame_cpu[k][c][f]);
        steady[k][c] *= 60.0 / 59.0;
      }
    std::printf(
        "without the first frame (cold estimate), CPU per simulated s RK4 / symplectic Euler: "
        "default %.3f / "
        "%.3f s = %.2fx, checks every 4th step %.3f / %.3f s = %.2fx, at frame ends only %.3f / "
        "%.3f s = "
        "%.2fx\n",
        steady[0][0], steady[1][0], steady[0][0] / steady[1][0], steady[0][2], steady[1][2],
        steady[0][2] / steady[1][2], steady[0][3], steady[1][3], steady[0][3] / steady[1][3]);
  }
  std::printf(
      "where the default configuration's CPU time goes (per simulated second; unit costs "
      "above):\n");
  for (int k = 0; k < 2; ++k) {
    // Per frame: the first step reuses f_int of the check that ended the
    // frame before (frame 1: of the check at the start), every later step
    // carries the check of its start state in its first force evaluation
    // (EnergyCheck::Bound for StVK: the orientation check only), and the
    // frame's end state gets a force evaluation with the full check.
    const Run& t = last[k][0];
    const int per_step = integs[k] == Integrator::RK4 ? 4 : 1;
    const long fused = t.substeps - 60, plain = t.substeps * (per_step - 1), end_checks = 61;
    const double evals = plain * t_eval + fused * t_orient + end_checks * t_health;
    const double lanczos = t.first_products * t_product + t.products * t_eval;
    const double total = cpu_med[k][0];
    std::printf(
        "  %-17s %.3f s: force evaluations %.3f s (%.0f%%: %ld plain, %ld with the fused check, "
        "%ld "
        "frame-end checks; the checks' share %.3f s), omega_max estimates %.3f s (%.0f%%: %ld cold "
        "products, then %ld warm ones in 59 frames), rest %.3f s (%.0f%%: node passes, step "
        "control, "
        "in-situ kernel slowdown)\n",
        to_string(integs[k]), total, evals, 100 * evals / total, plain, fused, end_checks,
        fused * (t_orient - t_eval) + end_checks * (t_health - t_eval), lanczos,
        100 * lanczos / total, t.first_products, t.products, total - evals - lanczos,
        100 * (total - evals - lanczos) / total);
  }
  std::printf("load average after: %s\n", load_average().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("fem_realtime", run, argc, argv);
}
