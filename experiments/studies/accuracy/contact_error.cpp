// contact_error: error of the approximate contact force and contact region
// against run time, for each collision budget and traversal mode (paper
// section 4.2 leaves accuracy unreported).
//
// The scene is run uninterrupted to the moment of contact of table1/fig9
// (`--after` frames past first contact). At that frozen state, every
// (mode, budget) query is repeated `--reps` times on the same sphere trees and
// the median-time repetition is evaluated (time budgets make the answer vary).
// References: the uninterrupted traversal (same trees, budget = inf) and the
// exact intersecting dense triangle pairs (AABB trees + exact tri-tri tests).
// Metrics (one CSV row per mode x budget):
//   force_rel_error   |F - F_full| / |F_full|, F = total penalty force on the
//                     first object (Eq. 11 summed over colliding + untested pairs)
//   force_angle_deg   angle between F and F_full
//   recall_full       fraction of the full traversal's colliding leaf pairs
//                     lying under a reported pair (both spheres descend from it)
//   recall_exact      fraction of exact intersecting triangle pairs (f, g)
//                     lying under a reported pair (a, b): sphere a meets
//                     triangle f and sphere b meets triangle g
//   false_positive    fraction of reported pairs under which no exact pair lies
//   volume_ratio      volume of the distinct first-object spheres reported /
//                     the same for the full traversal (how loose the region is)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <icd/collision/aabb_tree.hpp>
#include <icd/config.hpp>
#include <icd/coupling/contact_response.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/triangle_geometry.hpp>
#include <icd/mesh/io/atomic_write.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/studies/paper/contact_moment.hpp"

namespace fs = std::filesystem;
using namespace icd;
using namespace icd::runner;
using collision::CollisionRequest;
using collision::CollisionResult;
using collision::NodePair;
using collision::SphereTree;
using Eigen::Vector3d;

namespace {

// A triangle with a bounding ball for cheap rejection.
struct Tri {
  Vector3d a, b, c, centre;
  double radius = 0;
};

Tri make_tri(const MatX3d& V, const MatX3i& F, int f) {
  Tri t{V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(), V.row(F(f, 2)).transpose(), {}, 0};
  t.centre = (t.a + t.b + t.c) / 3;
  t.radius = std::max({(t.a - t.centre).norm(), (t.b - t.centre).norm(), (t.c - t.centre).norm()});
  return t;
}

bool meets(const collision::Sphere& s, const Tri& t) {
  const Vector3d c(s.x, s.y, s.z);
  if ((c - t.centre).norm() > s.r + t.radius) return false;
  return (closest_point_on_triangle(c, t.a, t.b, t.c) - c).norm() <= s.r;
}

bool is_ancestor_or_self(const std::vector<int32_t>& parent, int anc, int node) {
  for (; node >= 0; node = parent[node])
    if (node == anc) return true;
  return false;
}

struct Mode {
  std::string name;
  CollisionRequest request;
};

struct Metrics {
  double seconds = 0, response_seconds = 0, force_rel_error = 0, force_angle_deg = 0;
  double recall_full = 0, recall_exact = 0, false_positive = 0, volume_ratio = 0;
  int64_t tests = 0, reported = 0, colliding = 0;
  int completed_level = 0, interrupted = 0;
};

class Evaluator {
 public:
  Evaluator(const SphereTree& a, const SphereTree& b, const coupling::ContactOptions& contact,
            int na, int nb, std::vector<Tri> tri_a, std::vector<Tri> tri_b)
      : m_a(a),
        m_b(b),
        m_contact(contact),
        m_na(na),
        m_nb(nb),
        m_tri_a(std::move(tri_a)),
        m_tri_b(std::move(tri_b)),
        m_parent_a(collision::parents(a)),
        m_parent_b(collision::parents(b)) {
    CollisionRequest full;
    m_full = collision::collide(a, b, full);
    m_force_full = force(m_full, nullptr);
    m_volume_full = volume(m_full);
  }
  const CollisionResult& full() const { return m_full; }
  const Vector3d& force_full() const { return m_force_full; }

  Metrics evaluate(const CollisionResult& r) const {
    Metrics m;
    m.seconds = r.seconds;
    m.tests = r.tests;
    m.colliding = static_cast<int64_t>(r.colliding.size());
    m.reported = static_cast<int64_t>(r.colliding.size() + r.untested.size());
    m.completed_level = r.completed_level;
    m.interrupted = r.interrupted ? 1 : 0;
    const Vector3d f = force(r, &m.response_seconds);
    const double nf = m_force_full.norm();
    m.force_rel_error = nf > 0 ? (f - m_force_full).norm() / nf : (f.norm() > 0 ? 1.0 : 0.0);
    m.force_angle_deg =
        (nf > 0 && f.norm() > 0)
            ? std::acos(std::clamp(f.dot(m_force_full) / (f.norm() * nf), -1.0, 1.0)) * 180 /
                  std::numbers::pi
            : (nf > 0 || f.norm() > 0 ? 180.0 : 0.0);
    std::vector<NodePair> rep(r.colliding);
    rep.insert(rep.end(), r.untested.begin(), r.untested.end());
    // Recall against the full traversal.
    int covered = 0;
    for (const NodePair& leaf : m_full.colliding)
      for (const NodePair& p : rep)
        if (is_ancestor_or_self(m_parent_a, p.a, leaf.a) &&
            is_ancestor_or_self(m_parent_b, p.b, leaf.b)) {
          ++covered;
          break;
        }
    m.recall_full =
        m_full.colliding.empty() ? 1.0 : double(covered) / double(m_full.colliding.size());
    // Recall of the exact triangle pairs, and false positives.
    std::vector<char> useful(rep.size(), 0);
    int exact_covered = 0;
    for (size_t k = 0; k < m_tri_a.size(); ++k) {
      bool hit = false;
      for (size_t q = 0; q < rep.size(); ++q) {
        if (hit && useful[q]) continue;
        if (meets(m_a.spheres[rep[q].a], m_tri_a[k]) && meets(m_b.spheres[rep[q].b], m_tri_b[k])) {
          hit = true;
          useful[q] = 1;
        }
      }
      exact_covered += hit;
    }
    m.recall_exact = m_tri_a.empty() ? 1.0 : double(exact_covered) / double(m_tri_a.size());
    const auto n_useful = std::count(useful.begin(), useful.end(), 1);
    m.false_positive = rep.empty() ? 0.0 : 1.0 - double(n_useful) / double(rep.size());
    m.volume_ratio = m_volume_full > 0 ? volume(r) / m_volume_full : 0.0;
    return m;
  }

 private:
  Vector3d force(const CollisionResult& r, double* seconds) const {
    MatX3d fa = MatX3d::Zero(m_na, 3), fb = MatX3d::Zero(m_nb, 3);
    const auto t0 = std::chrono::steady_clock::now();
    const coupling::ContactStats st =
        coupling::apply_contact_forces(m_a, m_b, r, m_contact, fa, fb);
    if (seconds)
      *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return st.total_force_a;
  }
  double volume(const CollisionResult& r) const {
    std::vector<char> seen(m_a.spheres.size(), 0);
    double v = 0;
    for (const auto* list : {&r.colliding, &r.untested})
      for (const NodePair& p : *list)
        if (!seen[p.a]) {
          seen[p.a] = 1;
          v += 4.0 / 3.0 * std::numbers::pi * std::pow(m_a.spheres[p.a].r, 3);
        }
    return v;
  }

  const SphereTree& m_a;
  const SphereTree& m_b;
  coupling::ContactOptions m_contact;
  int m_na, m_nb;
  std::vector<Tri> m_tri_a, m_tri_b;  // exact intersecting pairs: m_tri_a[k] with m_tri_b[k]
  std::vector<int32_t> m_parent_a, m_parent_b;
  CollisionResult m_full;
  Vector3d m_force_full;
  double m_volume_full = 0;
};

int run(int argc, char** argv) {
  fs::path out = "results/contact_error";
  fs::path scene_path = fs::path(ICD_SOURCE_DIR) / "experiments/scenes/bunny_dragon.json";
  std::string budgets_text = "1e-6,3e-6,1e-5,3e-5,1e-4,3e-4,1e-3,3e-3,1e-2";
  std::string tests_text = "30,100,300,1000,3000,10000,30000,100000";
  int reps = 5, after = 3, max_frames = 200;
  std::vector<std::string> overrides;  // --set
  icd::experiments::Cli cli(
      "contact_error",
      "  Default scene experiments/scenes/bunny_dragon.json; writes DIR/contact_error.csv.");
  cli.path("--out", out, "DIR", "output folder (default results/contact_error)")
      .path("--scene", scene_path, "FILE", "scene file")
      .text("--budgets", budgets_text, "s1,s2,...", "critical times (s)")
      .text("--test-budgets", tests_text, "n1,n2,...", "sphere-test budgets")
      .integer("--reps", reps, "N", "repetitions per budget (default 5)", 1)
      .integer("--after", after, "N", "frames after first contact (default 3)", 0)
      .integer("--max-frames", max_frames, "N", "frames searched for contact (default 200)", 1);
  cli.scene_overrides(overrides);
  if (const auto status = cli.parse(argc, argv)) return *status;
  const std::vector<double> budgets = experiments::parse_list(budgets_text, "--budgets");
  const std::vector<double> test_budgets = experiments::parse_list(tests_text, "--test-budgets");
  Scene scene = load_scene(scene_path, overrides);
  scene.output = OutputSpec{};
  scene.world.target_fps = 0;
  scene.world.collision.query.budget_tests = -1;
  scene.world.collision.query.budget_seconds = std::numeric_limits<double>::infinity();
  World world = make_world(scene, fs::path(ICD_SOURCE_DIR) / "assets",
                           fs::canonical("/proc/self/exe").parent_path());
  if (world.plan().pairs.empty()) throw InputError(scene_path.string() + ": no collision pair");
  const experiments::ContactMoment cm = experiments::run_to_contact(world, max_frames, after);
  if (cm.contact_frame < 0)
    throw InputError(scene_path.string() + ": no contact within --max-frames");
  const auto [ia, ib] = world.plan().pairs[0];
  const RuntimeObject& oa = world.objects()[ia];
  const RuntimeObject& ob = world.objects()[ib];
  const MatX3d da = experiments::dense_positions(oa), db = experiments::dense_positions(ob);
  const collision::AabbTree ta(da, oa.asset.dense.F), tb(db, ob.asset.dense.F);
  const auto exact =
      collision::intersecting_triangle_pairs(ta, da, oa.asset.dense.F, tb, db, ob.asset.dense.F);
  std::vector<Tri> tri_a, tri_b;
  for (const auto& [f, g] : exact) {
    tri_a.push_back(make_tri(da, oa.asset.dense.F, f));
    tri_b.push_back(make_tri(db, ob.asset.dense.F, g));
  }
  const Evaluator ev(oa.asset.spheres, ob.asset.spheres, scene.world.collision.contact,
                     static_cast<int>(oa.positions.rows()), static_cast<int>(ob.positions.rows()),
                     tri_a, tri_b);
  const Metrics full = ev.evaluate(ev.full());
  std::printf(
      "%s: frame %d (contact at %d): %zu exact triangle pairs, full traversal %zu leaf pairs, "
      "%lld tests, |F_full| = %.4g N, exact recall of the full traversal %.3f\n",
      scene.name.c_str(), cm.last_frame, cm.contact_frame, exact.size(), ev.full().colliding.size(),
      static_cast<long long>(ev.full().tests), ev.force_full().norm(), full.recall_exact);

  std::vector<Mode> modes;
  const CollisionSpec& cs = scene.world.collision;
  auto base = [&] {
    CollisionRequest r;
    r.clock_check_interval = cs.query.clock_check_interval;
    return r;
  };
  modes.push_back({"fifo", base()});
  modes.push_back({"fifo_paper_literal", CollisionRequest::paper_reference(1)});
  CollisionRequest pr = base();
  pr.mode = collision::TraversalMode::Priority;
  pr.max_list_size = cs.query.max_list_size;
  modes.push_back({"priority", pr});
  pr.max_list_size = 256;
  modes.push_back({"priority_cap256", pr});
  CollisionRequest df = base();
  df.mode = collision::TraversalMode::DepthFirst;
  modes.push_back({"depth_first", df});

  std::ostringstream csv;
  csv << "scene,frame,mode,budget_kind,budget,seconds,response_seconds,tests,reported_pairs,"
         "colliding_pairs,completed_level,interrupted,force_rel_error,force_angle_deg,recall_"
         "full,"
         "recall_exact,false_positive,volume_ratio,exact_pairs,full_leaf_pairs,full_seconds\n";
  for (const Mode& mode : modes)
    for (int kind = 0; kind < 2; ++kind)
      for (double budget : kind == 0 ? budgets : test_budgets) {
        CollisionRequest req = mode.request;
        req.budget_seconds = kind == 0 ? budget : std::numeric_limits<double>::infinity();
        req.budget_tests = kind == 0 ? -1 : static_cast<int64_t>(budget);
        // Time every repetition; evaluate the median-time one (evaluation is costly).
        std::vector<CollisionResult> runs(reps);
        for (CollisionResult& run : runs) {
          // The first call sizes the result's vectors, so the timed one does not reallocate.
          collision::collide(oa.asset.spheres, ob.asset.spheres, req, run);
          collision::collide(oa.asset.spheres, ob.asset.spheres, req, run);
        }
        std::sort(runs.begin(), runs.end(), [](const CollisionResult& x, const CollisionResult& y) {
          return x.seconds < y.seconds;
        });
        const Metrics m = ev.evaluate(runs[runs.size() / 2]);
        csv << scene.name << ',' << cm.last_frame << ',' << mode.name << ','
            << (kind == 0 ? "seconds" : "tests") << ',' << budget << ',' << m.seconds << ','
            << m.response_seconds << ',' << m.tests << ',' << m.reported << ',' << m.colliding
            << ',' << m.completed_level << ',' << m.interrupted << ',' << m.force_rel_error << ','
            << m.force_angle_deg << ',' << m.recall_full << ',' << m.recall_exact << ','
            << m.false_positive << ',' << m.volume_ratio << ',' << exact.size() << ','
            << ev.full().colliding.size() << ',' << full.seconds << '\n';
        std::printf(
            "%-18s %-7s %-8g: %9.2e s, %7lld tests, force err %.3f, recall full %.3f exact %.3f, "
            "false pos %.3f\n",
            mode.name.c_str(), kind == 0 ? "seconds" : "tests", budget, m.seconds,
            static_cast<long long>(m.tests), m.force_rel_error, m.recall_full, m.recall_exact,
            m.false_positive);
      }
  fs::create_directories(out);
  write_file_atomically(out / "contact_error.csv", csv.str());
  std::printf("results: %s\n", fs::absolute(out / "contact_error.csv").c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("contact_error", run, argc, argv);
}
