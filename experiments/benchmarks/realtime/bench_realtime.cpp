// Real-time frames, side by side in one run: each scene runs as two Worlds
// stepped in turn frame by frame (1 thread: the previous code path; 2
// threads), then once in real-time mode at 60 Hz on 2 threads. Prints per
// frame medians of wall and CPU time (and the most FEM sub-steps of a frame), the real-time factor by wall clock,
// the speed-up, the share of frames that met the 60 Hz deadline, what the
// FEM costs per sub-step, and the load (/proc/loadavg) before and after.
//
// usage: bench_realtime [--frames N] [SCENE.json ...]
//   default scenes: experiments/scenes/bunny_dragon.json (the main job) and
//   experiments/scenes/many_objects.json; default 120 frames each.
#include "experiments/common/cli.hpp"
#include "experiments/common/process_exit.hpp"
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <limits>
#include <numeric>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <icd/collision/traversal.hpp>
#include <icd/config.hpp>
#include <icd/coupling/contact_response.hpp>
#include <icd/coupling/worker_pool.hpp>
#include <icd/mesh/core/error.hpp>
#include "experiments/runner/run.hpp"
#include "experiments/runner/scene.hpp"

namespace {

using icd::coupling::FrameMetrics;
using icd::coupling::World;

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// CPU time of the calling thread alone (the World's own thread; its
// workers and any other thread of the process excluded).
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string loadavg() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

// Where a World's frames go: the parallel region (each object's FEM, links
// and sphere update; FrameMetrics::times), the serial collision and
// response between cycles, and the rest (planning, snapshots, energy).
// Per cycle (World::set_cycle_observer) each object's own time in the
// region is summed, and the slower object's: the region's critical path.
struct Breakdown {
  std::vector<double> region, collision, response, rest, slower, cycles;
  std::vector<std::vector<double>> own;  ///< per object
  std::vector<double> frame_own;         ///< scratch: this frame's per object
  double frame_slower = 0;
  int frame_cycles = 0;
  void observe(const World& w) {
    frame_own.resize(w.objects().size(), 0.0);
    double slowest = 0;
    for (size_t k = 0; k < w.objects().size(); ++k) {
      const auto& o = w.objects()[k];
      const double t = o.stage_seconds[0] + o.stage_seconds[1] + o.stage_seconds[2];
      frame_own[k] += t;
      slowest = std::max(slowest, t);
    }
    frame_slower += slowest;
    ++frame_cycles;
  }
  void end_frame(const FrameMetrics& m, double wall) {
    const double r = m.times.fem + m.times.links + m.times.sphere_update;
    region.push_back(r);
    collision.push_back(m.times.collision);
    response.push_back(m.times.response);
    rest.push_back(wall - m.times.total());
    slower.push_back(frame_slower);
    cycles.push_back(frame_cycles);
    own.resize(frame_own.size());
    for (size_t k = 0; k < frame_own.size(); ++k) own[k].push_back(frame_own[k]);
    frame_own.assign(frame_own.size(), 0.0);
    frame_slower = 0;
    frame_cycles = 0;
  }
};

struct Series {
  std::vector<double> wall, cpu, thread_cpu, fem, substeps;
  double total_wall = 0;
  Breakdown parts;
  void add(const FrameMetrics& m, double wall_s, double cpu_s, double thread_cpu_s) {
    wall.push_back(wall_s);
    cpu.push_back(cpu_s);
    thread_cpu.push_back(thread_cpu_s);
    fem.push_back(m.times.fem);
    substeps.push_back(m.substeps);
    total_wall += wall_s;
    parts.end_frame(m, wall_s);
  }
  void watch(World& w) {
    w.set_cycle_observer([this](const World& world) { parts.observe(world); });
  }
};

FrameMetrics timed_step(World& w, Series& s) {
  const double c0 = cpu_seconds(), tc0 = thread_cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  const FrameMetrics m = w.step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.add(m, wall, cpu_seconds() - c0, thread_cpu_seconds() - tc0);
  return m;
}

// The breakdown of a series, medians per frame, ms.
void print_breakdown(const char* label, const Series& s, const World& w) {
  const Breakdown& b = s.parts;
  std::printf("  %-24s wall %.2f = region %.2f (critical path %.2f; own:", label, 1e3 * median(s.wall),
              1e3 * median(b.region), 1e3 * median(b.slower));
  for (size_t k = 0; k < b.own.size(); ++k)
    std::printf(" %s %.2f", w.objects()[k].setup.name.c_str(), 1e3 * median(b.own[k]));
  std::printf(") + collision %.2f + response %.2f + rest %.2f; cycles %.0f\n", 1e3 * median(b.collision),
              1e3 * median(b.response), 1e3 * median(b.rest), median(b.cycles));
}

// The ceiling of the 2-thread speed-up on this machine: the first two
// objects' FEM alone, advanced frame by frame (free flight, no contact) for
// `frames` frames, first one after the other on one thread (each timed),
// then on two threads that never synchronise (fresh copies of the same
// start). ideal = (t0 + t1) / max(t0, t1): the objects' imbalance alone;
// measured = (t0 + t1) / parallel; their ratio is what running two cores
// at once costs each of them (shared caches, memory, the host's scheduling).
void measure_ceiling(World& serial, World& parallel, int frames, double dt) {
  if (serial.objects().size() < 2 || !serial.objects()[0].sim || !serial.objects()[1].sim) return;
  const auto advance = [&](World& w, int k) {
    for (int f = 0; f < frames; ++f) w.objects()[static_cast<size_t>(k)].sim->advance(dt);
  };
  double t[2];
  for (int k = 0; k < 2; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    advance(serial, k);
    t[k] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  const double c0 = cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  std::thread other([&] { advance(parallel, 1); });
  advance(parallel, 0);
  other.join();
  const double both = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpu_seconds() - c0;
  std::printf("FEM alone, %d frames: object 0 %.2f ms/frame, object 1 %.2f ms/frame (1 thread); both on 2 "
              "threads %.2f ms/frame wall, %.2f CPU: speed-up %.2fx (ideal for this imbalance %.2fx; "
              "each object %.0f%% slower than alone)\n",
              frames, 1e3 * t[0] / frames, 1e3 * t[1] / frames, 1e3 * both / frames, 1e3 * cpu / frames,
              (t[0] + t[1]) / both, (t[0] + t[1]) / std::max(t[0], t[1]),
              100 * (both / std::max(t[0], t[1]) - 1));
}

// The cost of one hand-off of the objects to the workers (WorkerPool::run of
// two trivial tasks), median over 2000, with `gap_us` of serial work on the
// caller between two hand-offs (as the collision stage between two cycles),
// for a worker that blocks at once and one that spins first.
void measure_handoff() {
  for (const double gap_us : {0.0, 50.0}) {
    for (const double spin : {0.0, 100e-6}) {
      icd::coupling::WorkerPool pool(2, spin);
      std::vector<double> t;
      std::atomic<long> sink{0};
      const std::function<void(int)> job = [&](int k) { sink.fetch_add(k, std::memory_order_relaxed); };
      const double c0 = cpu_seconds();
      const auto w0 = std::chrono::steady_clock::now();
      for (int i = 0; i < 2000; ++i) {
        const auto g0 = std::chrono::steady_clock::now();
        while (std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - g0).count() < gap_us) {
        }
        const auto t0 = std::chrono::steady_clock::now();
        pool.run(2, job);
        t.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
      }
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
      std::printf("hand-off (2 tasks), %2.0f us serial work between: worker spin %3.0f us: median %.1f us, "
                  "CPU/wall of the loop %.2f\n",
                  gap_us, 1e6 * spin, median(t), (cpu_seconds() - c0) / wall);
    }
  }
}

void run_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides, int frames,
               const std::filesystem::path& tools, bool trace) {
  icd::runner::Scene scene = icd::runner::load_scene(path, overrides);
  const std::filesystem::path cache = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
  const double dt = 1.0 / scene.world.frame_rate;
  std::printf("\n== %s: %zu objects, %d frames of %.2f ms simulated, load before %s\n",
              scene.name.c_str(), scene.objects.size(), frames, 1e3 * dt, loadavg().c_str());
  std::fflush(stdout);
  scene.world.target_fps = 0;
  scene.world.threads = 1;
  World one = icd::runner::make_world(scene, cache, tools);
  for (const std::string& line : icd::runner::describe_mass_scaling(one))
    std::printf("%s\n", line.c_str());
  scene.world.threads = 2;
  World two = icd::runner::make_world(scene, cache, tools);
  scene.world.worker_spin = 100e-6;  // (workers that spin 100 us before they block)
  World spinning = icd::runner::make_world(scene, cache, tools);
  scene.world.worker_spin = icd::coupling::WorldSettings{}.worker_spin;
  Series s1, s2, s2b;
  s1.watch(one);
  s2.watch(two);
  for (int f = 0; f < frames; ++f) {  // interleaved, rotating which goes first
    World* worlds[3] = {&one, &two, &spinning};
    Series* series[3] = {&s1, &s2, &s2b};
    for (int k = 0; k < 3; ++k) timed_step(*worlds[(f + k) % 3], *series[(f + k) % 3]);
  }
  {
    scene.world.threads = 1;
    World a = icd::runner::make_world(scene, cache, tools);
    World b = icd::runner::make_world(scene, cache, tools);
    measure_ceiling(a, b, frames, dt);
    scene.world.threads = 2;
  }
  // 60 Hz real-time mode on 2 threads: the other cycle rule than the
  // scene's (collision.cycles_at_fem_step flipped), the scene's, and the
  // scene's with the single-cycle trial in every frame that starts apart
  // (collision.predict_contact off: the previous path).
  struct Rt {
    Series s;
    int met = 0, fem_over = 0, floored = 0, contact_frames = 0, deep_steps = 0, rollbacks = 0,
        predicted = 0;
    double worst = 0, depth_ratio = 0, penetration = 0, e0 = 0, e_end = 0;
    std::string warning;
  };
  const auto run_rt = [&](bool fem_step_cycles, bool predict, const char* label) {
    scene.world.target_fps = 60;
    scene.world.collision.cycles_at_fem_step = fem_step_cycles;
    scene.world.collision.predict_contact = predict;
    World rt = icd::runner::make_world(scene, cache, tools);
    Rt r;
    r.s.watch(rt);
    if (trace)
      std::printf("trace (%s): frame wall_ms fem_ms coll_ms resp_ms rest_ms cycles penalty motion "
                  "substeps products rollback predicted split active depth_ratio deep_steps capped "
                  "softened energy met\n",
                  label);
    for (int f = 0; f < frames; ++f) {
      const FrameMetrics m = timed_step(rt, r.s);
      r.met += m.deadline_met == 1;
      r.fem_over += m.fem_over_deadline;
      r.floored += m.min_budget_queries;
      r.worst = std::max(r.worst, m.lateness);
      r.contact_frames += m.active_pairs > 0;
      r.deep_steps += m.deep_steps;
      r.rollbacks += m.rollback;
      r.predicted += m.predicted;
      r.depth_ratio = std::max(r.depth_ratio, m.depth_ratio);
      r.penetration = std::max(r.penetration, m.max_penetration);
      if (f == 0) r.e0 = m.energy;
      r.e_end = m.energy;
      if (!m.deadline_warning.empty()) r.warning = m.deadline_warning;
      if (trace)
        std::printf("  %3d %7.2f %7.2f %6.2f %6.2f %6.2f %4d %4d %4d %4d %5d %d %d %d %5d %6.2f %4d "
                    "%6lld %3d %.4f %d\n",
                    m.frame, 1e3 * m.wall, 1e3 * m.times.fem, 1e3 * m.times.collision,
                    1e3 * m.times.response, 1e3 * (m.wall - m.times.total()), m.cycles,
                    m.cycles_penalty, m.cycles_motion, m.substeps, m.frequency_products, m.rollback,
                    m.predicted, m.subdivided, m.active_pairs, m.depth_ratio, m.deep_steps,
                    static_cast<long long>(m.capped_pairs), m.softened, m.energy, m.deadline_met);
    }
    return r;
  };
  const bool at_step = scene.world.collision.cycles_at_fem_step;  // (the scene's or the default)
  const Rt s3 = run_rt(!at_step, true, at_step ? "stiffness cycle rule" : "cycles_at_fem_step");
  const Rt s4 = run_rt(at_step, true, at_step ? "cycles_at_fem_step (the scene's)" : "the scene's cycle rule");
  const Rt s5 = run_rt(at_step, false, "the scene's cycle rule, always the trial");
  scene.world.collision.predict_contact = true;
  scene.world.collision.cycles_at_fem_step = at_step;
  const double sim = frames * dt;
  std::printf("%-26s %12s %12s %12s %10s %10s %14s %12s %12s\n", "", "wall ms/fr", "CPU ms/fr",
              "thread CPU", "x real", "FEM ms/fr", "sub-steps/fr", "us/sub-step", "max sub/fr");
  const auto row = [&](const char* label, const Series& s) {
    const double sub = median(s.substeps);
    std::printf("%-26s %12.2f %12.2f %12.2f %10.2f %10.2f %14.0f %12.1f %12.0f\n", label,
                1e3 * median(s.wall), 1e3 * median(s.cpu), 1e3 * median(s.thread_cpu),
                sim / s.total_wall, 1e3 * median(s.fem), sub,
                sub > 0 ? 1e6 * median(s.fem) / sub : 0.0,
                *std::max_element(s.substeps.begin(), s.substeps.end()));
  };
  row("1 thread (old path)", s1);
  row("2 threads", s2);
  row("2 threads, workers spin", s2b);
  row(at_step ? "2 thr, 60 Hz RT, stiff rule" : "2 thr, 60 Hz RT, at step", s3.s);
  row("2 threads, 60 Hz RT", s4.s);
  row("2 thr, 60 Hz RT, trial", s5.s);
  std::printf("speed-up 2 vs 1 thread (median wall per frame): %.2fx (workers that spin 100 us: %.2fx)\n",
              median(s1.wall) / median(s2.wall), median(s1.wall) / median(s2b.wall));
  std::printf("where the frames go (medians per frame, ms; CPU: the whole process, thread CPU: the "
              "World's own thread):\n");
  print_breakdown("1 thread", s1, one);
  print_breakdown("2 threads", s2, two);
  const std::pair<const char*, const Rt*> rts[] = {
      {at_step ? " (stiffness cycle rule: cycles_at_fem_step off)" : " (cycles_at_fem_step)", &s3},
      {"", &s4},
      {" (always the single-cycle trial)", &s5}};
  for (const auto& [label, r] : rts) {
    std::printf("real-time mode at 60 Hz%s: %d of %d frames met the deadline (%.1f%%), worst lateness "
                "%.2f ms, FEM alone over the deadline in %d frames, %d queries at the minimum budget\n",
                label, r->met, frames, 100.0 * r->met / frames, 1e3 * r->worst, r->fem_over, r->floored);
    std::printf("  contact: %d frames with contact, deepest leaf pair %.2f leaf radii (%.2f mm), %d "
                "deep velocity steps, energy %.4f -> %.4f J; %d frames cycled at once (contact "
                "predicted), %d single-cycle trials rolled back\n",
                r->contact_frames, r->depth_ratio, 1e3 * r->penetration, r->deep_steps, r->e0, r->e_end,
                r->predicted, r->rollbacks);
    if (!r->warning.empty()) std::printf("  %s\n", r->warning.c_str());
  }
  std::printf("load after %s\n", loadavg().c_str());
  std::fflush(stdout);
}

// Level of detail for many pairs (--lod): the scene with its own query
// budget, shared among the pairs evenly, by priority and cheapest first
// (three runs). After
// every detection/response cycle (World::set_cycle_observer, rolled-back
// cycles included) each pair's query answer is compared with an unlimited
// query on the same spheres (the oracle): the penalty force (Eq. 11, the
// paper's response to the query as it stands) of each pair the oracle finds
// in contact, relative error |F - F_exact| / |F_exact| (1 for a contact the
// query missed). Time: the collision stage per frame (mean), and the
// frame's wall time without the oracle's (median).
void run_lod(const std::filesystem::path& path, const std::vector<std::string>& overrides,
             int frames, const std::filesystem::path& tools) {
  icd::runner::Scene scene = icd::runner::load_scene(path, overrides);
  const std::filesystem::path cache = std::filesystem::path(ICD_SOURCE_DIR) / "assets";
  std::printf("\n== %s, level of detail: %d frames, budget %g s / %lld tests per query, load %s\n",
              scene.name.c_str(), frames, scene.world.collision.query.budget_seconds,
              static_cast<long long>(scene.world.collision.query.budget_tests), loadavg().c_str());
  std::printf("%-10s %8s %12s %12s %12s %8s %12s %12s %10s\n", "split", "samples", "median err",
              "p90 err", "max err", "missed", "coll ms/fr", "wall ms/fr", "interrupt");
  struct PairErrors {
    std::vector<double> even, priority;
    // Same state (the priority or cheapest run's cycles): the World's answer
    // and the even split's answer of the same spheres, with the tests each used.
    std::vector<double> same_even, same_priority, tests_even, tests_priority;
  };
  std::vector<PairErrors> per_pair;
  for (const icd::coupling::BudgetSplit split :
       {icd::coupling::BudgetSplit::Even, icd::coupling::BudgetSplit::Priority,
        icd::coupling::BudgetSplit::Cheapest}) {
    const bool even = split == icd::coupling::BudgetSplit::Even;
    const char* split_name = even ? "even"
                             : split == icd::coupling::BudgetSplit::Priority ? "priority"
                                                                             : "cheapest";
    if (!even)  // the even run's per-pair errors stay; the same-state ones are per run
      for (PairErrors& pe : per_pair) {
        pe.priority.clear();
        pe.same_even.clear();
        pe.same_priority.clear();
        pe.tests_even.clear();
        pe.tests_priority.clear();
      }
    scene.world.collision.budget_split = split;
    scene.world.target_fps = 0;
    World w = icd::runner::make_world(scene, cache, tools);
    per_pair.resize(w.plan().pairs.size());
    std::vector<double> err, coll, wall;
    int interrupted = 0, missed = 0;
    double oracle_seconds = 0;
    icd::collision::CollisionRequest exact = scene.world.collision.query;
    exact.budget_seconds = std::numeric_limits<double>::infinity();
    exact.budget_tests = -1;
    exact.start_front = nullptr;
    exact.record_front = false;
    icd::collision::CollisionResult oracle, even_answer;
    icd::collision::CollisionRequest even_request = scene.world.collision.query;
    even_request.start_front = nullptr;
    even_request.record_front = false;
    w.set_cycle_observer([&](const World& world) {
      const auto o0 = std::chrono::steady_clock::now();
      const auto& pairs = world.plan().pairs;
      for (size_t p = 0; p < pairs.size(); ++p) {
        const auto& a = world.objects()[pairs[p].first];
        const auto& b = world.objects()[pairs[p].second];
        icd::collision::collide(a.asset.spheres, b.asset.spheres, exact, oracle);
        if (oracle.colliding.empty()) continue;
        icd::coupling::ContactOptions co = scene.world.collision.contact;
        icd::MatX3d fa = icd::MatX3d::Zero(a.positions.rows(), 3), fb = icd::MatX3d::Zero(b.positions.rows(), 3);
        const Eigen::Vector3d truth = icd::coupling::apply_contact_forces(
            a.asset.spheres, b.asset.spheres, oracle, co, fa, fb).total_force_a;
        if (truth.norm() == 0) continue;
        fa.setZero();
        fb.setZero();
        const icd::collision::CollisionResult& got_r = world.results()[p];
        const Eigen::Vector3d got = icd::coupling::apply_contact_forces(
            a.asset.spheres, b.asset.spheres, got_r, co, fa, fb).total_force_a;
        const double e = (got - truth).norm() / truth.norm();
        missed += got_r.colliding.empty() && got_r.untested.empty();
        err.push_back(e);
        (even ? per_pair[p].even : per_pair[p].priority).push_back(e);
        if (!even && !scene.world.collision.temporal_coherence) {
          // The even split's answer in the same state: every pair its own
          // budget (World: CollisionSpec::query as is).
          icd::collision::collide(a.asset.spheres, b.asset.spheres, even_request, even_answer);
          fa.setZero();
          fb.setZero();
          const Eigen::Vector3d alt = icd::coupling::apply_contact_forces(
              a.asset.spheres, b.asset.spheres, even_answer, co, fa, fb).total_force_a;
          per_pair[p].same_even.push_back((alt - truth).norm() / truth.norm());
          per_pair[p].same_priority.push_back(e);
          per_pair[p].tests_even.push_back(static_cast<double>(even_answer.tests));
          per_pair[p].tests_priority.push_back(static_cast<double>(got_r.tests));
        }
      }
      oracle_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - o0).count();
    });
    for (int f = 0; f < frames; ++f) {
      const double before = oracle_seconds;
      const auto t0 = std::chrono::steady_clock::now();
      const FrameMetrics m = w.step();
      wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() -
                     (oracle_seconds - before));
      coll.push_back(m.times.collision);
      interrupted += m.interrupted;
    }
    std::vector<double> sorted = err;
    std::sort(sorted.begin(), sorted.end());
    const double p90 = sorted.empty() ? 0 : sorted[static_cast<size_t>(0.9 * (sorted.size() - 1))];
    std::printf("%-10s %8zu %12.3f %12.3f %12.3f %8d %12.3f %12.2f %10d\n", split_name,
                err.size(), median(err), p90, sorted.empty() ? 0 : sorted.back(), missed,
                1e3 * std::accumulate(coll.begin(), coll.end(), 0.0) / frames, 1e3 * median(wall),
                interrupted);
    std::fflush(stdout);
    if (!even) {
      std::printf("per pair (samples: cycles the oracle found the pair in contact): median error even / %s\n",
                  split_name);
      for (size_t p = 0; p < per_pair.size(); ++p) {
        if (per_pair[p].even.empty() && per_pair[p].priority.empty()) continue;
        const auto& pr = w.plan().pairs[p];
        std::printf("  %-12s %-12s %6zu %8.3f   %6zu %8.3f\n", w.objects()[pr.first].setup.name.c_str(),
                    w.objects()[pr.second].setup.name.c_str(), per_pair[p].even.size(),
                    median(per_pair[p].even), per_pair[p].priority.size(), median(per_pair[p].priority));
      }
      std::printf("same state (the %s run's cycles; each pair's answer with its %s "
                  "budget and with the even budget of the same spheres): samples, median error "
                  "even / %s, mean error even / %s, median tests even / %s\n",
                  split_name, split_name, split_name, split_name, split_name);
      std::vector<double> all_even, all_prio;
      for (size_t p = 0; p < per_pair.size(); ++p) {
        const PairErrors& pe = per_pair[p];
        if (pe.same_even.empty()) continue;
        const auto mean = [](const std::vector<double>& v) {
          return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
        };
        const auto& pr = w.plan().pairs[p];
        std::printf("  %-12s %-12s %6zu %8.3f %8.3f   %8.3f %8.3f   %7.0f %7.0f\n",
                    w.objects()[pr.first].setup.name.c_str(), w.objects()[pr.second].setup.name.c_str(),
                    pe.same_even.size(), median(pe.same_even), median(pe.same_priority), mean(pe.same_even),
                    mean(pe.same_priority), median(pe.tests_even), median(pe.tests_priority));
        all_even.insert(all_even.end(), pe.same_even.begin(), pe.same_even.end());
        all_prio.insert(all_prio.end(), pe.same_priority.begin(), pe.same_priority.end());
      }
      if (!all_even.empty())
        std::printf("  all pairs    %6zu samples: median error even %.3f, %s %.3f; mean %.3f, %.3f\n",
                    all_even.size(), median(all_even), split_name, median(all_prio),
                    std::accumulate(all_even.begin(), all_even.end(), 0.0) / all_even.size(),
                    std::accumulate(all_prio.begin(), all_prio.end(), 0.0) / all_prio.size());
    }
  }
  std::printf("load after %s\n", loadavg().c_str());
}

}  // namespace

int main(int argc, char** argv) {
  icd::experiments::exit_without_library_shutdown_under_memory_limits();
  int frames = 120;
  bool lod = false, trace = false;
  std::vector<std::filesystem::path> scenes;
  std::vector<std::string> overrides;
  icd::experiments::Cli cli(
      "bench_realtime",
      "  Each scene stepped with 1 thread (the previous path) and 2 threads, interleaved frame by\n"
      "  frame, then in real-time mode at 60 Hz; wall and CPU time per frame (medians).\n"
      "  Default scenes: experiments/scenes/bunny_dragon.json and many_objects.json.");
  cli.arguments("SCENE", scenes, "scene files (JSON)", false)
      .integer("--frames", frames, "N", "frames per configuration (default 120)", 1, 100000)
      .flag("--lod", lod,
            "level of detail for many pairs instead: the scene's query budget shared evenly, "
            "by priority and cheapest pairs first, per-pair contact force error against an unlimited query of the same "
            "spheres, and collision time")
      .flag("--trace", trace,
            "print one line per frame of the real-time runs: wall, FEM and collision ms, cycles and "
            "the bounds they came from, sub-steps, Lanczos products, contact depth, energy")
      .scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  if (scenes.empty()) {
    const std::filesystem::path root(ICD_SOURCE_DIR);
    scenes = {root / "experiments/scenes/bunny_dragon.json",
              root / "experiments/scenes/many_objects.json"};
  }
  const std::filesystem::path tools =
      std::filesystem::absolute(std::filesystem::path(argv[0])).parent_path();
  std::printf("bench_realtime: %u hardware threads; load %s\n",
              std::max(1u, static_cast<unsigned>(std::thread::hardware_concurrency())),
              loadavg().c_str());
  if (!lod) measure_handoff();
  try {
    for (const auto& s : scenes)
      lod ? run_lod(s, overrides, frames, tools) : run_scene(s, overrides, frames, tools, trace);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_realtime: %s\n", e.what());
    return 1;
  }
  return 0;
}
