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
// as bunny-dragon collides again and again. A relaunch is external work: it
// replaces the kinetic energy. With relaunches the energy bound applies to
// each launch: the objects' largest energy until the next relaunch must stay
// below --energy-factor times their energy just after the relaunch (the
// previous frame's energy with its kinetic part replaced by the new one).
// The energy bounded is the objects' own (kinetic + elastic + gravity): the
// frame's energy column also holds the penalty springs of the last response,
// which for an interrupted query are springs between coarse spheres assumed
// colliding, a number the objects never receive in full (see the runner's
// collision.passive). Both ratios to the initial energy are reported.
#include <vector>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include <icd/config.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/runner/run.hpp"
#include "experiments/studies/reliability/soak_scene.hpp"

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

/// The options, bound to the fields of `a`.
void add_options(icd::experiments::Cli& cli, Args& a) {
  cli.integer("--frames", a.frames, "N", "frames (default 100000)", 1)
      .integer("--every", a.every, "K", "report every K frames (default 1000)", 1)
      .custom("--budget-tests", "B", "sphere tests per query, -1: none (default 2000)",
              [&a](const std::string& v) {
                a.budget_tests = icd::experiments::Cli::parse_integer<long long>(v, -1);
                a.budget_given = true;
              })
      .text("--scene", a.scene, "FILE", "soak this scene instead of the ball between walls")
      .real("--speed", a.speed, "V", "initial speed (default 1)", 0.0)
      .real("--energy-factor", a.energy_factor, "F", "energy bound over the initial (default 1.5)",
            0.0)
      .real("--max-growth-mb", a.max_growth_mb, "M", "resident memory growth allowed (default 16)",
            0.0)
      .integer("--relaunch", a.relaunch, "K", "relaunch every K frames, 0: never (default 0)", 0)
      .text("--csv", a.csv, "FILE", "also write the rows as CSV");
}

// Each deformable object gets its initial speed towards the centroid of the
// others. Returns the change of kinetic energy (J).
double relaunch(icd::runner::World& world) {
  auto& objects = world.objects();
  double change = 0;
  if (objects.size() < 2) return change;
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
    v.rowwise() = (o.setup.velocity.norm() / d.norm() * d).transpose();
    change -= o.sim->model().kinetic_energy(o.sim->velocities());
    o.sim->set_velocities(v);  // zero at fixed nodes
    change += o.sim->model().kinetic_energy(o.sim->velocities());
  }
  return change;
}

int run(int argc, char** argv) {
  using namespace icd;
  Args a;
  std::vector<std::string> overrides;  // --set
  icd::experiments::Cli cli("soak", "  See the comment at the top of soak.cpp.");
  add_options(cli, a);
  cli.scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  runner::Scene scene;
  if (a.scene.empty()) {
    reliability::ContactBoxOptions o;
    o.budget_tests = a.budget_tests;
    o.speed = a.speed;
    scene = reliability::make_contact_box_scene(o);
  } else {
    scene = runner::load_scene(a.scene, overrides);
    if (a.budget_given) reliability::use_test_budget(scene, a.budget_tests);
  }
  runner::World world =
      runner::make_world(scene, std::filesystem::path(ICD_SOURCE_DIR) / "assets", ICD_TOOL_DIR);
  std::FILE* csv = a.csv.empty() ? nullptr : std::fopen(a.csv.c_str(), "w");
  const char* header =
      "frame,fps,rss_mb,energy,penalty_energy,max_energy_ratio,max_object_energy_ratio,"
      "max_launch_gain,contact_frames,tests,interrupted\n";
  if (csv) std::fputs(header, csv);
  std::printf("%s", header);

  double e0 = -1, max_ratio = 0, max_object_ratio = 0, rss_first = -1, rss_max = 0;
  // Energy just after the current launch, the largest energy since, and the
  // largest ratio of the two over all launches (the bound checked).
  double e_launch = -1, e_prev = 0, max_gain = 0;
  int worst_launch_frame = 0;
  long long contact_frames = 0, tests = 0, interrupted = 0;
  bool failed = false;
  auto t_window = std::chrono::steady_clock::now();
  const auto t_start = t_window;
  for (int f = 0; f < a.frames; ++f) {
    if (a.relaunch > 0 && f > 0 && f % a.relaunch == 0) e_launch = e_prev + relaunch(world);
    const runner::FrameMetrics m = world.step();
    if (e0 < 0) e0 = m.energy;
    if (e_launch < 0) e_launch = e0;
    const double e_objects = m.energy - m.penalty_energy;
    e_prev = e_objects;
    max_object_ratio = std::max(max_object_ratio, e0 > 0 ? e_objects / e0 : 0.0);
    if (e_launch > 0 && e_objects / e_launch > max_gain) {
      max_gain = e_objects / e_launch;
      worst_launch_frame = a.relaunch > 0 ? f - f % a.relaunch : 0;
    }
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
      std::snprintf(row, sizeof row, "%d,%.1f,%.1f,%.6g,%.6g,%.4f,%.4f,%.4f,%lld,%lld,%lld\n",
                    f + 1, n / dt, rss, m.energy, m.penalty_energy, max_ratio, max_object_ratio,
                    max_gain, contact_frames, tests, interrupted);
      std::fputs(row, stdout);
      std::fflush(stdout);
      if (csv) {
        std::fputs(row, csv);
        std::fflush(csv);  // a stopped run keeps its windows
      }
    }
  }
  if (csv) std::fclose(csv);
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  std::printf(
      "soak: %d frames in %.1f s (%.1f fps), initial energy %.6g J, max energy ratio "
      "%.4f (objects %.4f, with the penalty springs %.4f), %lld frames with contact, "
      "%lld interrupted queries, RSS first window %.1f MB, max %.1f MB\n",
      a.frames, total, a.frames / total, e0, max_object_ratio, max_object_ratio, max_ratio,
      contact_frames, interrupted, rss_first, rss_max);
  if (a.relaunch > 0)
    std::printf(
        "soak: largest object energy within a launch / energy at its start: %.4f "
        "(launch at frame %d)\n",
        max_gain, worst_launch_frame);
  if (max_gain > a.energy_factor) {
    std::fprintf(stderr, "soak: FAIL energy grew to %.4f x the energy at %s (limit %.4f)\n",
                 max_gain, a.relaunch > 0 ? "the start of its launch" : "the start",
                 a.energy_factor);
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
}

}  // namespace

int main(int argc, char** argv) { return icd::experiments::guarded_main("soak", run, argc, argv); }
