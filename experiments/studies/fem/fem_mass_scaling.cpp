// Selective mass scaling: what it adds and what it costs in accuracy, on the
// coarse meshes of a scene (default: the main job, bunny and dragon).
//  1. Per object and target ratio: added mass, max factor, nodes, the
//     stable-step ratio before/after (Lanczos), the time the scaling takes,
//     and the relative change of the lowest elastic vibration frequencies of
//     the free object (dense generalized eigenproblem with and without the
//     added mass).
//  2. The scene run for --frames frames with the scaling off and at the
//     scene's target, collision budget 1000 s, i.e. unlimited (deterministic): centre of
//     mass paths (unscaled lumped masses), node positions, max contact force,
//     RK4 sub-steps per frame.
//
// usage: fem_mass_scaling [--frames N] [--modes K] [SCENE.json] [--set KEY=VALUE ...]
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include <icd/config.hpp>
#include <icd/fem/mass.hpp>
#include <icd/fem/mass_scaling.hpp>
#include <icd/fem/model.hpp>
#include "experiments/runner/run.hpp"
#include "experiments/runner/scene.hpp"

namespace {

using icd::MatX3d;
using icd::coupling::World;

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string loadavg() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

// Square roots of the eigenvalues of K u = lambda diag(mass) u, ascending.
Eigen::VectorXd frequencies(const Eigen::MatrixXd& K, const Eigen::VectorXd& mass) {
  Eigen::VectorXd s(K.rows());
  for (Eigen::Index i = 0; i < K.rows(); ++i) s[i] = 1.0 / std::sqrt(mass[i / 3]);
  const Eigen::MatrixXd A = s.asDiagonal() * K * s.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .cwiseMax(0.0)
      .cwiseSqrt();
}

struct Trace {
  std::vector<std::vector<Eigen::Vector3d>> com;  // per frame, per object
  std::vector<std::vector<MatX3d>> x;             // per frame, per object (coarse nodes)
  std::vector<double> contact;                    // per frame
  std::vector<int> substeps;                      // per frame
  double wall = 0, cpu = 0;
};

Trace run(const icd::runner::Scene& scene, const std::filesystem::path& tools, int frames,
          const std::vector<Eigen::VectorXd>& physical_mass) {
  const std::filesystem::path cache = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
  World w = icd::runner::make_world(scene, cache, tools);
  for (const std::string& line : icd::runner::describe_mass_scaling(w)) std::printf("  %s\n", line.c_str());
  Trace t;
  const double c0 = cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) {
    const icd::coupling::FrameMetrics m = w.step();
    t.contact.push_back(m.contact_force);
    t.substeps.push_back(m.substeps);
    std::vector<Eigen::Vector3d> com;
    std::vector<MatX3d> xs;
    for (size_t k = 0; k < w.objects().size(); ++k) {
      const auto& o = w.objects()[k];
      if (!o.sim) continue;
      const MatX3d& x = o.sim->positions();
      const Eigen::VectorXd& mass = physical_mass[k];
      com.push_back((x.transpose() * mass) / mass.sum());
      xs.push_back(x);
    }
    t.com.push_back(com);
    t.x.push_back(xs);
  }
  t.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t.cpu = cpu_seconds() - c0;
  return t;
}

int run_study(int argc, char** argv) {
  int frames = 60, modes = 10;
  std::filesystem::path scene_path =
      std::filesystem::path(ICD_SOURCE_DIR) / "experiments/scenes/bunny_dragon.json";
  std::vector<std::string> overrides;
  icd::experiments::Cli cli(
      "fem_mass_scaling",
      "  Selective mass scaling on a scene's coarse meshes (default: the main job): added mass\n"
      "  and step ratio per target, change of the lowest vibration frequencies (dense), and\n"
      "  the scene run with the scaling off and on (collision budget 1000 s, i.e. unlimited): centre-of-\n"
      "  mass paths, node positions, max contact force, sub-steps per frame.");
  cli.argument("SCENE", scene_path, "scene file (JSON)", false)
      .integer("--frames", frames, "N", "frames of each run (default 60)", 1, 100000)
      .integer("--modes", modes, "K", "lowest elastic modes compared (default 10)", 1, 100)
      .scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  const std::filesystem::path tools =
      std::filesystem::absolute(std::filesystem::path(argv[0])).parent_path();
  std::printf("fem_mass_scaling: %s, load %s\n", scene_path.c_str(), loadavg().c_str());
  // The scene with the scaling off: the objects' coarse meshes and materials.
  std::vector<std::string> off = overrides, on = overrides;
  off.push_back("collision.budget_seconds=1000");
  on.push_back("collision.budget_seconds=1000");
  icd::runner::Scene base = icd::runner::load_scene(scene_path, off);
  for (size_t k = 0; k < base.objects.size(); ++k)
    off.push_back("objects." + std::to_string(k) + ".fem.mass_scaling_target=0");
  const icd::runner::Scene scene_off = icd::runner::load_scene(scene_path, off);
  const icd::runner::Scene scene_on = icd::runner::load_scene(scene_path, on);
  const std::filesystem::path cache = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
  World probe = icd::runner::make_world(scene_off, cache, tools);
  std::vector<Eigen::VectorXd> physical;
  std::printf(
      "\n== 1. per object and target: the scaling and the lowest %d elastic frequencies "
      "of the free object (dense)\n",
      modes);
  std::printf("%-8s %6s %6s %8s %7s %9s %7s %7s %9s %9s %9s %s\n", "object", "nodes", "target",
              "added %", "scaled", "max fac.", "before", "after", "ms wall", "ms CPU", "max |dw|/w",
              "per mode |dw|/w %");
  for (size_t k = 0; k < probe.objects().size(); ++k) {
    auto& o = probe.objects()[k];
    physical.push_back(
        o.sim ? icd::fem::lumped_mass(o.sim->model().mesh(), o.sim->model().material().density)
              : Eigen::VectorXd());
    if (!o.sim) continue;
    const MatX3d rest = o.rest;
    const icd::MatX4i T = o.asset.coarse.T;
    const icd::fem::Material mat = o.sim->model().material();
    icd::fem::Model plain(rest, T, mat);
    const Eigen::MatrixXd K = Eigen::MatrixXd(plain.elastic().stiffness(rest));
    const Eigen::VectorXd w0 = frequencies(K, plain.mass());
    for (double target : {0.4, 0.5, 0.6}) {
      icd::fem::ModelOptions mo;
      mo.mass_scaling.target_ratio = target;
      const double c0 = cpu_seconds();
      const auto t0 = std::chrono::steady_clock::now();
      icd::fem::Model scaled(rest, T, mat, mo);
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double cpu = cpu_seconds() - c0;
      const icd::fem::MassScalingReport& r = scaled.mass_scaling();
      const Eigen::VectorXd w1 = frequencies(K, scaled.mass());
      double worst = 0;
      std::string per;
      for (int m = 6; m < 6 + modes && m < w0.size(); ++m) {
        const double d = std::abs(w1[m] - w0[m]) / w0[m];
        worst = std::max(worst, d);
        char b[32];
        std::snprintf(b, sizeof b, " %.3f", 100 * d);
        per += b;
      }
      std::printf("%-8s %6d %6.2f %8.3f %7d %9.1f %7.3f %7.3f %9.1f %9.1f %9.4f%%%s\n",
                  o.setup.name.c_str(), plain.num_nodes(), target, 100 * r.added_fraction,
                  r.scaled_nodes, r.max_factor, r.ratio_before, r.ratio_after, 1e3 * wall,
                  1e3 * cpu, 100 * worst, per.c_str());
    }
    std::printf("%-8s lowest elastic frequencies unscaled (Hz):", o.setup.name.c_str());
    for (int m = 6; m < 6 + modes && m < w0.size(); ++m) std::printf(" %.2f", w0[m] / (2 * M_PI));
    std::printf("\n");
  }
  std::printf(
      "\n== 2. the scene for %d frames, scaling off and at the scene's target "
      "(collision.budget_seconds 1000: unlimited), load %s\n",
      frames, loadavg().c_str());
  const Trace a = run(scene_off, tools, frames, physical);
  const Trace b = run(scene_on, tools, frames, physical);
  // Sizes: bounding-box diagonals of the coarse meshes.
  std::vector<double> diag;
  for (const auto& o : probe.objects())
    if (o.sim) diag.push_back((o.rest.colwise().maxCoeff() - o.rest.colwise().minCoeff()).norm());
  for (size_t k = 0; k < diag.size(); ++k) {
    double com_err = 0, travel = 0, node_err = 0;
    for (int f = 0; f < frames; ++f) {
      com_err = std::max(com_err, (a.com[f][k] - b.com[f][k]).norm());
      travel = std::max(travel, (a.com[f][k] - a.com[0][k]).norm());
      node_err =
          std::max(node_err, std::sqrt((a.x[f][k] - b.x[f][k]).rowwise().squaredNorm().mean()));
    }
    std::printf(
        "object %zu: max |COM off - COM on| %.3g m = %.3f %% of its diagonal (%.3g m), "
        "%.3f %% of the COM travel (%.3g m); max RMS node distance %.3g m = %.3f %% of "
        "the diagonal\n",
        k, com_err, 100 * com_err / diag[k], diag[k], 100 * com_err / std::max(travel, 1e-300),
        travel, node_err, 100 * node_err / diag[k]);
  }
  const double fa = *std::max_element(a.contact.begin(), a.contact.end());
  const double fb = *std::max_element(b.contact.begin(), b.contact.end());
  const auto fa_at = std::max_element(a.contact.begin(), a.contact.end()) - a.contact.begin();
  const auto fb_at = std::max_element(b.contact.begin(), b.contact.end()) - b.contact.begin();
  double rms = 0;
  for (int f = 0; f < frames; ++f) rms += std::pow(a.contact[f] - b.contact[f], 2);
  rms = std::sqrt(rms / frames);
  std::printf(
      "max contact force: off %.4g N (frame %ld), on %.4g N (frame %ld): relative "
      "difference %.2f %%; RMS per-frame difference %.3g N = %.2f %% of the max\n",
      fa, static_cast<long>(fa_at), fb, static_cast<long>(fb_at), 100 * (fb - fa) / fa, rms,
      100 * rms / fa);
  auto stats = [](const std::vector<int>& s) {
    std::vector<int> v = s;
    std::sort(v.begin(), v.end());
    return std::make_pair(v[v.size() / 2], v.back());
  };
  const auto sa = stats(a.substeps), sb = stats(b.substeps);
  std::printf("sub-steps per frame (both objects): off median %d max %d; on median %d max %d\n",
              sa.first, sa.second, sb.first, sb.second);
  std::printf(
      "run time (unlimited queries, 1 World, scene threads): off %.2f s wall %.2f s CPU, "
      "on %.2f s wall %.2f s CPU\n",
      a.wall, a.cpu, b.wall, b.cpu);
  std::printf("load after %s\n", loadavg().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("fem_mass_scaling", run_study, argc, argv);
}
