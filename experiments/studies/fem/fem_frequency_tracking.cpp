// How well the per-frame re-estimate of omega_max tracks the truth, and how
// much stable-step safety margin that leaves. The fem_realtime bar (3,840
// tets, E = 1e6 Pa, StVK, clamped, gravity, alpha = 1) sags and swings for
// 3 s with RK4 and automatic steps; at the start state of every frame the
// Simulator's warm Lanczos re-estimate (FrequencyEstimate::omega_bound) is
// compared with a converged cold-start Lanczos estimate (300 iterations,
// tolerance 1e-9). Printed per re-estimate configuration (warm Ritz vectors,
// iterations, tolerance): mean Lanczos products per frame and the worst
// bound / truth ratio (< 1: the step limit was too large by that factor).
// Then each integrator with safety factors 0.9 (default), 0.95, 0.97 and 1:
// sub-steps, rollbacks, and whether the run completed.
//
// Usage: fem_frequency_tracking (no options; --help)
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/studies/fem/clamped_bar.hpp"
#include <icd/fem/simulator.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace {

using namespace icd;
using namespace icd::fem;

int run(int argc, char** argv) {
  icd::experiments::Cli cli("fem_frequency_tracking",
                            "  Prints how the per-frame omega_max re-estimate tracks the truth and "
                            "the\n  safety margin per integrator (see the top of "
                            "fem_frequency_tracking.cpp).");
  if (const auto status = cli.parse(argc, argv)) return *status;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  BoxMeshOptions bo;
  bo.nx = 40;
  bo.ny = 4;
  bo.nz = 4;
  bo.size = Eigen::Vector3d(1.0, 0.1, 0.1);
  const TetMesh m = make_box_tet_mesh(bo);
  const int frames = 180;
  struct Config {
    int warm_modes, iterations;
    double tolerance;
  };
  const Config configs[] = {{1, 4, 1e-5}, {1, 4, 1e-2}, {1, 6, 1e-3}, {2, 5, 1e-3},
                            {3, 4, 1e-2}, {3, 5, 1e-3}, {3, 6, 1e-3}, {3, 8, 1e-4}};
  std::printf(
      "bar 3840 tets, RK4, %d frames of 1/60 s; omega bound of the per-frame re-estimate vs "
      "converged\n",
      frames);
  for (const Config& c : configs) {
    Model reference = clamped_stvk_model(m);
    SimulatorOptions so;
    so.frequency.warm_modes = c.warm_modes;
    so.frequency_refresh_iterations = c.iterations;
    so.frequency_refresh_tolerance = c.tolerance;
    Simulator sim(clamped_stvk_model(m), so);
    FrequencyOptions converged;
    converged.max_iterations = 300;
    converged.tolerance = 1e-9;
    double worst = 1e300, lo = 1e300, hi = 0;
    long products = 0;
    int worst_frame = -1;
    for (int f = 0; f < frames; ++f) {
      const double truth = estimate_max_frequency(reference, sim.positions(), converged).omega_max;
      sim.advance(1.0 / 60);  // re-estimates at the same (frame start) state
      if (f > 0) products += sim.last_frequency().iterations;
      const double ratio = sim.last_frequency().omega_bound / truth;
      lo = std::min(lo, truth);
      hi = std::max(hi, truth);
      if (ratio < worst) {
        worst = ratio;
        worst_frame = f;
      }
    }
    std::printf(
        "warm Ritz vectors %d, <= %d iterations, tolerance %.0e: %.2f products per frame, worst "
        "bound / "
        "truth %.4f (frame %d); converged omega_max %.0f .. %.0f rad/s\n",
        c.warm_modes, c.iterations, c.tolerance, static_cast<double>(products) / (frames - 1),
        worst, worst_frame, lo, hi);
  }
  for (Integrator integ : {Integrator::RK4, Integrator::SymplecticEuler})
    for (double safety : {0.9, 0.95, 0.97, 1.0}) {
      SimulatorOptions so;
      so.integrator = integ;
      so.safety_factor = safety;
      Simulator sim(clamped_stvk_model(m), so);
      long substeps = 0;
      int retries = 0;
      std::string outcome = "completed";
      try {
        for (int f = 0; f < frames; ++f) {
          const AdvanceReport r = sim.advance(1.0 / 60);
          substeps += r.substeps;
          retries += r.retries;
        }
      } catch (const std::exception& e) {
        outcome = std::string("stopped: ") + e.what();
      }
      std::printf("%-17s safety %.2f (default re-estimate): %ld substeps, %d rollbacks, %s\n",
                  to_string(integ), safety, substeps, retries, outcome.substr(0, 160).c_str());
    }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("fem_frequency_tracking", run, argc, argv);
}
