// Accuracy experiments of the collision module (issue 6):
//  1. Coverage of the deformed dense surface by the updated leaf spheres: the
//     paper's ratio update vs the conservative displacement bound (with the
//     paper's nearest-node association), for growing deformation.
//  2. Accuracy per unit time of the traversal modes on two overlapping
//     dragons: FIFO (paper), best-first with capped lists, depth-first. The
//     accuracy of an (interrupted) answer: dense vertices of object A lying in
//     an A-sphere of a reported pair, relative to the full traversal's count
//     (1 = as tight as a full traversal; larger = more surface suspected).
//  3. Temporal coherence: repeated budgeted queries on a moving scene, from the
//     roots every frame vs from the previous front.
//
// Usage: icd_collision_accuracy [--levels L]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include <icd/collision/coverage.hpp>
#include <icd/collision/sphere_update.hpp>
#include <icd/collision/traversal.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/studies/collision/workloads.hpp"

using namespace icd::collision;
using namespace icd::collision::experiments;
using Clock = std::chrono::steady_clock;

namespace {

// Number of points inside at least one of the spheres (uniform grid).
long long points_covered(const std::vector<Sphere>& spheres, const icd::MatX3d& P, double h) {
  auto key = [](long long a, long long b, long long c) {
    return (a * 73856093LL) ^ (b * 19349663LL) ^ (c * 83492791LL);
  };
  std::unordered_map<long long, std::vector<int>> grid;
  for (int i = 0; i < static_cast<int>(spheres.size()); ++i) {
    const Sphere& s = spheres[i];
    for (long long a = std::floor((s.x - s.r) / h); a <= std::floor((s.x + s.r) / h); ++a)
      for (long long b = std::floor((s.y - s.r) / h); b <= std::floor((s.y + s.r) / h); ++b)
        for (long long c = std::floor((s.z - s.r) / h); c <= std::floor((s.z + s.r) / h); ++c)
          grid[key(a, b, c)].push_back(i);
  }
  long long n = 0;
  for (int v = 0; v < P.rows(); ++v) {
    auto it =
        grid.find(key(std::floor(P(v, 0) / h), std::floor(P(v, 1) / h), std::floor(P(v, 2) / h)));
    if (it == grid.end()) continue;
    for (int i : it->second) {
      const Sphere& s = spheres[i];
      const double dx = P(v, 0) - s.x, dy = P(v, 1) - s.y, dz = P(v, 2) - s.z;
      if (dx * dx + dy * dy + dz * dz <= s.r * s.r) {
        ++n;
        break;
      }
    }
  }
  return n;
}

long long suspected_vertices(const Object& a, const CollisionResult& r) {
  std::vector<char> seen(a.tree.num_nodes(), 0);
  std::vector<Sphere> s;
  for (const auto* list : {&r.colliding, &r.untested})
    for (const NodePair& p : *list)
      if (!seen[p.a]) {
        seen[p.a] = 1;
        s.push_back(a.tree.spheres[p.a]);
      }
  return points_covered(s, a.dense.V, 0.05);
}

void coverage_experiment(const std::string& file, int levels) {
  Object o = load_object(file, {0, 0, 0}, levels);
  std::printf(
      "\n[1] %s, octree %d levels (%d spheres), %ld coarse nodes (nearest-node association):\n",
      file.c_str(), levels, o.tree.num_nodes(), (long)o.coarse_rest.rows());
  std::printf("%10s %28s %28s %28s\n", "amplitude", "paper ratio: uncovered/gap",
              "conservative: uncov./gap", "conservative+0.01: uncov.");
  std::printf(
      "  (model side 2; gap = largest distance of an uncovered dense vertex outside the leaf "
      "spheres)\n");
  for (double amp : {0.0, 0.05, 0.1, 0.2, 0.3, 0.5}) {
    const icd::MatX3d x = deform(o.coarse_rest, amp, 0.5), V = deform(o.dense.V, amp, 0.5);
    SphereUpdateOptions opt;
    update_spheres(o.tree, o.coarse_rest, x, opt);
    const CoverageReport p = measure_coverage(o.tree, V);
    opt.mode = SphereUpdateMode::DisplacementBound;
    update_spheres(o.tree, o.coarse_rest, x, opt);
    const CoverageReport c = measure_coverage(o.tree, V);
    opt.margin = 0.01;
    update_spheres(o.tree, o.coarse_rest, x, opt);
    const CoverageReport m = measure_coverage(o.tree, V);
    std::printf("%10.2f %18.4f%% / %6.4f %18.4f%% / %6.4f %27.4f%%\n", amp,
                100 * p.uncovered_fraction, p.max_gap, 100 * c.uncovered_fraction, c.max_gap,
                100 * m.uncovered_fraction);
  }
}

void modes_experiment(int levels) {
  Object a = load_object("ChineseDragon-10kv.off", {0, 0, 0}, levels);
  Object b = load_object("ChineseDragon-10kv.off", {0.45, 0.15, 0.05}, levels);
  CollisionResult full;
  collide(a.tree, b.tree, CollisionRequest{}, full);
  const double full_count = static_cast<double>(suspected_vertices(a, full));
  std::printf(
      "\n[2] two dragons, octree %d levels (%d spheres each): full traversal %lld tests, %zu leaf "
      "pairs, "
      "%.0f dense vertices of A suspected\n",
      levels, a.tree.num_nodes(), (long long)full.tests, full.colliding.size(), full_count);
  std::printf("%-28s %9s %10s %12s %10s %8s\n", "mode", "tests", "time us", "suspected/full",
              "peak list", "level");
  struct Mode {
    const char* name;
    CollisionRequest r;
  };
  std::vector<Mode> modes;
  modes.push_back({"FIFO literal (paper)", CollisionRequest::paper_reference(INFINITY)});
  modes.push_back({"FIFO fast path", CollisionRequest{}});
  for (std::size_t cap : {64, 1024}) {
    CollisionRequest r;
    r.mode = TraversalMode::Priority;
    r.max_list_size = cap;
    modes.push_back({cap == 64 ? "priority largest, cap 64" : "priority largest, cap 1024", r});
  }
  {
    CollisionRequest r;
    r.mode = TraversalMode::Priority;
    r.priority = PriorityKey::DeepestOverlap;
    r.max_list_size = 1024;
    modes.push_back({"priority deepest, cap 1024", r});
  }
  {
    CollisionRequest r;
    r.mode = TraversalMode::DepthFirst;
    modes.push_back({"depth-first (Fig. 4)", r});
  }
  for (const Mode& m : modes) {
    for (double frac : {0.02, 0.05, 0.1, 0.25, 0.5, 1.0}) {
      CollisionRequest r = m.r;
      r.budget_tests = static_cast<int64_t>(frac * full.tests);
      CollisionResult res;
      std::vector<double> times;
      for (int rep = 0; rep < 7; ++rep) {
        const auto t0 = Clock::now();
        collide(a.tree, b.tree, r, res);
        times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      }
      std::printf("%-28s %9lld %10.1f %14.2f %10zu %8d\n", m.name, (long long)res.tests,
                  1e6 * median(times), suspected_vertices(a, res) / full_count, res.peak_list_size,
                  res.completed_level);
    }
  }
}

void coherence_experiment(int levels) {
  for (const double fraction : {1.0 / 3.0, 0.9}) {
    Object a = load_object("ChineseDragon-10kv.off", {0, 0, 0}, levels);
    Object b = load_object("ChineseDragon-10kv.off", {0.45, 0.15, 0.05}, levels);
    CollisionResult full;
    collide(a.tree, b.tree, CollisionRequest{}, full);
    const int64_t budget = static_cast<int64_t>(fraction * full.tests);
    std::printf(
        "\n[3] temporal coherence, two dragons moving slowly, budget %lld tests (%.2f of a full "
        "traversal):\n",
        (long long)budget, fraction);
    std::printf("%6s %22s %22s %12s\n", "frame", "from roots: susp/full", "from front: susp/full",
                "front size");
    CollisionRequest r;
    r.budget_tests = budget;
    r.record_front = true;
    std::vector<NodePair> front;
    for (int frame = 0; frame < 8; ++frame) {
      for (Sphere& s : b.tree.spheres) s.x -= 0.002;
      CollisionResult ref, roots, coh;
      collide(a.tree, b.tree, CollisionRequest{}, ref);
      const double ref_count = static_cast<double>(suspected_vertices(a, ref));
      collide(a.tree, b.tree, r, roots);
      CollisionRequest rc = r;
      rc.start_front = frame == 0 ? nullptr : &front;
      collide(a.tree, b.tree, rc, coh);
      std::printf("%6d %22.2f %22.2f %12zu\n", frame, suspected_vertices(a, roots) / ref_count,
                  suspected_vertices(a, coh) / ref_count, front.size());
      front = coh.front;
    }
  }
}

int run(int argc, char** argv) {
  int levels = 6;
  icd::experiments::Cli cli("icd_collision_accuracy");
  cli.integer("--levels", levels, "L", "sphere-tree levels (default 6)", 1);
  if (const auto status = cli.parse(argc, argv)) return *status;
  coverage_experiment("ChineseDragon-10kv.off", 4);
  coverage_experiment("ChineseDragon-10kv.off", 6);
  coverage_experiment("bunny00.off", 6);
  modes_experiment(levels);
  coherence_experiment(levels);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("icd_collision_accuracy", run, argc, argv);
}
