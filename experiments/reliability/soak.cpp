// soak: a long run with repeated contact at a tight budget (issue 9). By
// default a deformable ball bouncing between two static walls (see
// soak_scene.hpp); --scene FILE soaks a scene file instead (e.g. the
// bunny-dragon scene; its budget is replaced by --budget-tests when given).
// Every --every frames it prints frames per second over the window, the
// resident memory (/proc/self/statm), the total energy and the contact
// count, and writes the same rows to --csv. Fails (exit 1) on a non-finite
// position or energy, an energy above --energy-factor times the initial one,
// or resident memory that grows by more than --max-growth-mb after the
// first window.
// usage: soak [--frames N=100000] [--every K=1000] [--budget-tests B=2000]
//             [--scene FILE] [--speed V=1] [--energy-factor F=1.5]
//             [--max-growth-mb M=16] [--relaunch K=0] [--csv FILE]
// --relaunch K: every K frames, give each deformable object its initial
// speed again (keeping its deformation), aimed at the centroid of the other
// objects: objects that bounced apart come back, so a two-object scene such
// as bunny-dragon collides again and again.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "experiments/reliability/soak_scene.hpp"
#include "experiments/runner/world.hpp"
#include "icd/config.hpp"

namespace {

double resident_mb() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1048576.0;
}

struct Args {
  int frames = 100000;
  int every = 1000;
  long long budget_tests = 2000;
  bool budget_given = false;
  std::string scene;
  double speed = 1.0;
  double energy_factor = 1.5;
  double max_growth_mb = 16;
  int relaunch = 0;
  std::string csv;
};

Args parse_args(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (i + 1 >= argc) {
      std::fprintf(stderr, "soak: %s needs a value\n", k.c_str());
      std::exit(2);
    }
    const char* v = argv[++i];
    if (k == "--frames") a.frames = std::atoi(v);
    else if (k == "--every") a.every = std::max(1, std::atoi(v));
    else if (k == "--budget-tests") { a.budget_tests = std::atoll(v); a.budget_given = true; }
    else if (k == "--scene") a.scene = v;
    else if (k == "--speed") a.speed = std::atof(v);
    else if (k == "--energy-factor") a.energy_factor = std::atof(v);
    else if (k == "--max-growth-mb") a.max_growth_mb = std::atof(v);
    else if (k == "--csv") a.csv = v;
    else if (k == "--relaunch") a.relaunch = std::max(0, std::atoi(v));
    else {
      std::fprintf(stderr, "soak: unknown argument %s\n", k.c_str());
      std::exit(2);
    }
  }
  return a;
}

// Each deformable object gets its initial speed towards the centroid of the others.
void relaunch(icd::runner::World& world) {
  auto& objects = world.objects();
  if (objects.size() < 2) return;
  for (size_t i = 0; i < objects.size(); ++i) {
    icd::runner::RuntimeObject& o = objects[i];
    if (!o.sim) continue;
    Eigen::Vector3d target = Eigen::Vector3d::Zero();
    for (size_t j = 0; j < objects.size(); ++j)
      if (j != i) target += objects[j].positions.colwise().mean().transpose();
    target /= static_cast<double>(objects.size() - 1);
    const Eigen::Vector3d d = target - o.positions.colwise().mean().transpose();
    if (d.norm() <= 0) continue;
    icd::MatX3d v(o.positions.rows(), 3);
    v.rowwise() = (o.spec.velocity.norm() / d.norm() * d).transpose();
    o.sim->set_velocities(v);  // zero at fixed nodes
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace icd;
  const Args a = parse_args(argc, argv);
  try {
    runner::Scene scene;
    if (a.scene.empty()) {
      reliability::ContactBoxOptions o;
      o.budget_tests = a.budget_tests;
      o.speed = a.speed;
      scene = reliability::make_contact_box_scene(o);
    } else {
      scene = runner::load_scene(a.scene);
      if (a.budget_given) reliability::use_test_budget(scene, a.budget_tests);
    }
    runner::World world(scene, std::filesystem::path(ICD_SOURCE_DIR) / "assets", ICD_TOOL_DIR);
    std::FILE* csv = a.csv.empty() ? nullptr : std::fopen(a.csv.c_str(), "w");
    const char* header = "frame,fps,rss_mb,energy,max_energy_ratio,contact_frames,tests,interrupted\n";
    if (csv) std::fputs(header, csv);
    std::printf("%s", header);

    double e0 = -1, max_ratio = 0, rss_first = -1, rss_max = 0;
    long long contact_frames = 0, tests = 0, interrupted = 0;
    bool failed = false;
    auto t_window = std::chrono::steady_clock::now();
    const auto t_start = t_window;
    for (int f = 0; f < a.frames; ++f) {
      if (a.relaunch > 0 && f > 0 && f % a.relaunch == 0) relaunch(world);
      const runner::FrameMetrics m = world.step();
      if (e0 < 0) e0 = m.energy;
      bool finite = std::isfinite(m.energy);
      for (runner::RuntimeObject& o : world.objects()) finite = finite && o.positions.allFinite();
      if (!finite) {
        std::fprintf(stderr, "soak: FAIL frame %d: non-finite position or energy\n", f);
        failed = true;
        break;
      }
      max_ratio = std::max(max_ratio, e0 > 0 ? m.energy / e0 : 0.0);
      contact_frames += m.active_pairs > 0;
      tests += m.tests;
      interrupted += m.interrupted;
      if ((f + 1) % a.every == 0 || f + 1 == a.frames) {
        const auto now = std::chrono::steady_clock::now();
        const double dt = std::chrono::duration<double>(now - t_window).count();
        const int n = (f + 1) % a.every == 0 ? a.every : (f + 1) % a.every;
        t_window = now;
        const double rss = resident_mb();
        if (rss_first < 0) rss_first = rss;
        rss_max = std::max(rss_max, rss);
        char row[256];
        std::snprintf(row, sizeof row, "%d,%.1f,%.1f,%.6g,%.4f,%lld,%lld,%lld\n", f + 1, n / dt,
                      rss, m.energy, max_ratio, contact_frames, tests, interrupted);
        std::fputs(row, stdout);
        std::fflush(stdout);
        if (csv) std::fputs(row, csv);
      }
    }
    if (csv) std::fclose(csv);
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    std::printf("soak: %d frames in %.1f s (%.1f fps), initial energy %.6g J, max energy ratio "
                "%.4f, %lld frames with contact, %lld interrupted queries, RSS first window "
                "%.1f MB, max %.1f MB\n",
                a.frames, total, a.frames / total, e0, max_ratio, contact_frames, interrupted,
                rss_first, rss_max);
    if (max_ratio > a.energy_factor) {
      std::fprintf(stderr, "soak: FAIL energy grew to %.4f x the initial energy (limit %.4f)\n",
                   max_ratio, a.energy_factor);
      failed = true;
    }
    if (rss_max - rss_first > a.max_growth_mb) {
      std::fprintf(stderr, "soak: FAIL resident memory grew by %.1f MB (limit %.1f MB)\n",
                   rss_max - rss_first, a.max_growth_mb);
      failed = true;
    }
    if (contact_frames == 0) {
      std::fprintf(stderr, "soak: FAIL no contact happened: the scene does not test contact\n");
      failed = true;
    }
    return failed ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "soak: %s\n", e.what());
    return 1;
  }
}
