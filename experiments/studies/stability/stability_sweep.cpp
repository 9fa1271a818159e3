// stability_sweep: stiff and extreme cases of the full simulation loop (FEM,
// sphere update, interruptible collision detection, penalty response). Each
// case is a variation of a base scene of two colliding primitive objects:
// Young's modulus 1e4..1e9 Pa, Poisson ratio 0.3..0.49, penalty stiffness over
// four orders of magnitude, large initial velocities, 70 % initial
// compression (the first object's coarse nodes squeezed to 30 % of their rest
// extent along x, then released), and the stiffest cases with backward Euler.
// For each case: whether the run stayed stable, the FEM step sizes chosen, the
// energy drift, the frame rate. A case that throws (unsupported combination,
// failed step) is recorded with the exception's message; nothing ends in NaN
// silently: non-finite positions or energy are reported as "unstable".
// Writes stability.csv and stability.md into --out.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <icd/config.hpp>
#include <icd/mesh/io/atomic_write.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/runner/run.hpp"

namespace fs = std::filesystem;
using namespace icd;
using namespace icd::runner;

namespace {

struct Case {
  std::string group, name;
  std::function<void(Scene&)> edit;
  double compression = 0;  // fraction of the first object's x extent removed at the start
};

struct Outcome {
  std::string status = "stable";  // stable | unstable | error | timeout
  std::string message;
  int frames = 0;
  double min_step = 0, mean_step = 0, fps = 0;
  double energy0 = 0, energy_end = 0, energy_max = 0, drift = 0, max_gain = 0;
  double max_penetration = 0;
};

Scene base_scene() {
  Scene s;
  s.name = "stability";
  s.frames = 60;
  s.world.frame_rate = 60;
  for (int side = 0; side < 2; ++side) {
    ObjectSpec o;
    o.name = side ? "right" : "left";
    o.primitive = PrimitiveSpec{};
    o.primitive->radius = 0.1;
    o.primitive->subdivisions = 2;
    o.primitive->cells = 4;
    o.preprocess.tree_depth = 3;
    o.position = Eigen::Vector3d(side ? 0.12 : -0.12, 0, 0);
    o.velocity = Eigen::Vector3d(side ? -0.6 : 0.6, 0, 0);
    o.material.young = 5e5;
    o.material.poisson = 0.3;
    o.material.density = 1000;
    o.damping.alpha = 0.5;
    o.integrator = fem::Integrator::RK4;
    s.objects.push_back(o);
  }
  s.world.collision.query.budget_tests = 100000;
  s.world.collision.query.budget_seconds = std::numeric_limits<double>::infinity();
  s.world.collision.layered = true;
  s.world.collision.contact.stiffness = 2000;
  s.output = OutputSpec{};
  s.output.csv = false;
  return s;
}

std::vector<Case> make_cases(bool quick) {
  std::vector<Case> cases;
  auto for_all = [](std::function<void(ObjectSpec&)> f) {
    return [f](Scene& s) {
      for (ObjectSpec& o : s.objects) f(o);
    };
  };
  char buf[64];
  for (double e :
       quick ? std::vector<double>{1e4, 1e9} : std::vector<double>{1e4, 1e5, 1e6, 1e7, 1e8, 1e9}) {
    std::snprintf(buf, sizeof buf, "E = %g Pa", e);
    cases.push_back({"young", buf, for_all([e](ObjectSpec& o) { o.material.young = e; }), 0});
  }
  for (double nu : quick ? std::vector<double>{0.49} : std::vector<double>{0.3, 0.4, 0.45, 0.49}) {
    std::snprintf(buf, sizeof buf, "nu = %g", nu);
    cases.push_back({"poisson", buf, for_all([nu](ObjectSpec& o) { o.material.poisson = nu; }), 0});
  }
  for (double k :
       quick ? std::vector<double>{1e2, 1e6} : std::vector<double>{1e2, 1e3, 1e4, 1e5, 1e6}) {
    std::snprintf(buf, sizeof buf, "k = %g N/m", k);
    cases.push_back({"penalty", buf, [k](Scene& s) { s.world.collision.contact.stiffness = k; }, 0});
  }
  for (double v : quick ? std::vector<double>{20} : std::vector<double>{2, 5, 10, 20}) {
    std::snprintf(buf, sizeof buf, "speed %g m/s each, head-on", v);
    cases.push_back({"velocity", buf,
                     [v](Scene& s) {
                       s.objects[0].velocity = Eigen::Vector3d(v, 0, 0);
                       s.objects[1].velocity = Eigen::Vector3d(-v, 0, 0);
                     },
                     0});
  }
  cases.push_back({"compression", "70 % along x, released", [](Scene&) {}, 0.7});
  cases.push_back({"compression", "70 % along x, stable Neo-Hookean", for_all([](ObjectSpec& o) {
                     o.material.model = fem::MaterialModel::StableNeoHookean;
                   }),
                   0.7});
  cases.push_back({"compression", "70 % along x, E = 1e7 Pa, nu = 0.45", for_all([](ObjectSpec& o) {
                     o.material.young = 1e7;
                     o.material.poisson = 0.45;
                   }),
                   0.7});
  for (double e : quick ? std::vector<double>{1e9} : std::vector<double>{1e7, 1e9}) {
    std::snprintf(buf, sizeof buf, "backward Euler, E = %g Pa", e);
    cases.push_back({"implicit", buf, for_all([e](ObjectSpec& o) {
                       o.material.young = e;
                       o.integrator = fem::Integrator::BackwardEuler;
                     }),
                     0});
  }
  return cases;
}

// Kinetic + elastic energy of the deformable objects, J (without the potential
// of the contact loads, which depends on where the objects are).
double mechanical_energy(World& world) {
  double e = 0;
  for (RuntimeObject& o : world.objects())
    if (o.sim) {
      fem::Model& model = o.sim->model();
      e += model.kinetic_energy(o.sim->velocities()) + model.elastic().energy(o.sim->positions());
    }
  return e;
}

Outcome run_case(const Case& c, int frames, double max_seconds) {
  Scene scene = base_scene();
  scene.frames = frames;
  c.edit(scene);
  scene.objects[0].initial_compression = c.compression;  // the scene field (run.cpp applies it)
  Outcome out;
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  int total_substeps = 0, deformables = 0;
  try {
    World world = make_world(scene, fs::path(ICD_SOURCE_DIR) / "assets",
                fs::canonical("/proc/self/exe").parent_path());
    for (const RuntimeObject& o : world.objects()) deformables += o.sim ? 1 : 0;
    // Reference energy: kinetic + elastic before the first step.
    out.energy0 = mechanical_energy(world);
    out.min_step = std::numeric_limits<double>::infinity();
    const double wall0 = elapsed();
    for (int f = 0; f < frames; ++f) {
      const FrameMetrics m = world.step();
      out.frames = f + 1;
      total_substeps += m.substeps;
      if (m.min_step > 0) out.min_step = std::min(out.min_step, m.min_step);
      out.max_penetration = std::max(out.max_penetration, m.max_penetration);
      const double energy = mechanical_energy(world);
      bool finite = std::isfinite(energy);
      for (const RuntimeObject& o : world.objects()) finite = finite && o.positions.allFinite();
      if (!finite) {
        out.status = "unstable";
        out.message = "non-finite energy or positions at frame " + std::to_string(f);
        break;
      }
      out.energy_end = energy;
      out.energy_max = std::max(out.energy_max, energy);
      if (elapsed() > max_seconds && f + 1 < frames) {
        out.status = "timeout";
        out.message = "stopped after " + std::to_string(f + 1) + " frames (over " +
                      std::to_string(static_cast<int>(max_seconds)) + " s of wall time)";
        break;
      }
    }
    const double wall = elapsed() - wall0;
    out.fps = out.frames / std::max(wall, 1e-12);
  } catch (const std::exception& e) {
    out.status = "error";
    out.message = e.what();
  }
  if (!std::isfinite(out.min_step)) out.min_step = 0;
  if (total_substeps > 0 && deformables > 0)
    out.mean_step = out.frames / scene.world.frame_rate * deformables / total_substeps;
  if (out.energy0 > 0 && out.frames > 0 && out.energy_max > 0) {
    out.drift = (out.energy_end - out.energy0) / out.energy0;
    out.max_gain = out.energy_max / out.energy0 - 1;
  }
  // Energy may not grow past twice its initial (kinetic + elastic) value
  // (penalty contacts may inject some; a blow-up injects orders of magnitude).
  if (out.status == "stable" && out.max_gain > 1.0) {
    out.status = "unstable";
    out.message = "energy grew to " + std::to_string(1 + out.max_gain) + " x its initial value";
  }
  return out;
}

std::string csv_escape(std::string s) {
  std::replace(s.begin(), s.end(), '"', '\'');
  std::replace(s.begin(), s.end(), '\n', ' ');
  return '"' + s + '"';
}

std::string md_escape(std::string s) {
  std::replace(s.begin(), s.end(), '|', '/');
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

int run(int argc, char** argv) {
  fs::path out = "results/stability";
  int frames = 30;
  double max_seconds = 30;
  bool quick = false;
  icd::experiments::Cli cli(
      "stability_sweep",
      "  Runs every case for N frames (default 30 = 0.5 simulated second), at most S s of\n"
      "  wall time each (default 30); --quick runs the extreme cases only.");
  cli.path("--out", out, "DIR", "output folder (default results/stability)")
      .integer("--frames", frames, "N", "frames per case", 1)
      .real("--max-seconds", max_seconds, "S", "wall-time limit per case", 0.0)
      .flag("--quick", quick, "the extreme cases only");
  if (const auto status = cli.parse(argc, argv)) return *status;
  std::ostringstream csv, md;
  csv << "group,case,status,frames,min_step,mean_step,energy_initial,energy_end,energy_drift,"
         "max_energy_gain,max_penetration,fps,message\n";
  md << "| group | case | status | frames | min step (s) | mean step (s) | energy drift | max "
        "energy gain | "
        "max penetration (m) | frames/s | message "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  int failures = 0;
  for (const Case& c : make_cases(quick)) {
    const Outcome o = run_case(c, frames, max_seconds);
    failures += o.status != "stable";
    char line[512];
    std::snprintf(line, sizeof line,
                  "%-12s %-38s %-8s %3d frames, step min %.3g mean %.3g s, drift %+.3g, "
                  "gain %.3g, %.1f fps %s\n",
                  c.group.c_str(), c.name.c_str(), o.status.c_str(), o.frames, o.min_step,
                  o.mean_step, o.drift, o.max_gain, o.fps, o.message.c_str());
    std::fputs(line, stdout);
    std::fflush(stdout);
    csv << c.group << ',' << csv_escape(c.name) << ',' << o.status << ',' << o.frames << ','
        << o.min_step << ',' << o.mean_step << ',' << o.energy0 << ',' << o.energy_end << ','
        << o.drift << ',' << o.max_gain << ',' << o.max_penetration << ',' << o.fps << ','
        << csv_escape(o.message) << '\n';
    char row[512];
    std::snprintf(
        row, sizeof row, "| %s | %s | %s | %d | %.3g | %.3g | %+.3g | %.3g | %.3g | %.1f | %s |\n",
        c.group.c_str(), c.name.c_str(), o.status.c_str(), o.frames, o.min_step, o.mean_step,
        o.drift, o.max_gain, o.max_penetration, o.fps, md_escape(o.message).c_str());
    md << row;
  }
  fs::create_directories(out);
  write_file_atomically(out / "stability.csv", csv.str());
  write_file_atomically(out / "stability.md", md.str());
  std::printf("%d of the cases not stable (see the table); results: %s\n", failures,
              fs::absolute(out).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("stability_sweep", run, argc, argv);
}
