// Our sphere-tree update and full traversal against (1) a near-limit loop of
// our own doing the same work on the same data (near_limit.hpp) and (2) the
// Flexible Collision Library used as its users use it on deforming meshes
// (issue 31 item 4). One thread, one process, on two overlapping deforming
// dragons and two overlapping deforming bunnies, at several tree sizes.
//
// Per frame both objects are deformed by a smooth field. FCL: one
// BVHModel<AABBd> per object over the dense triangles, built once and refit
// in place every frame (beginReplaceModel / replaceVertex /
// endReplaceModel(refit, bottom-up)), the CollisionObjects reused
// (computeAABB); queries through FCL's own mesh traversal node on the models
// (fcl::detail::initialize + fcl::detail::collide), since the public
// fcl::collide copies both BVHModel<AABB> models on every call (that call is
// shown too). Both FCL's first-contact and all-contacts queries.
// Ours: update_spheres (paper ratio and displacement bound), collide (full
// traversal, fast path, the default request).
// Timing: every operation runs once per round, all operations of a frame
// interleaved (ours, near-limit and FCL alternate; ours and the near-limit
// loop swap who goes first every round, each first in half the runs), `--rounds` rounds per
// frame; each run is timed in wall time (steady clock) and CPU time of the
// thread (CLOCK_THREAD_CPUTIME_ID); the tables give medians over all
// frames x rounds. The load average is printed at the start and the end.
// The near-limit loops are checked on every frame: identical spheres, leaf
// pairs and test counts, else the program says so and exits 1.
//
// Trees: our octree trees over every k-th dense vertex as coarse nodes, or,
// with --dragon-bundle / --bunny-bundle, the runner's medial-axis tree and
// coarse tet nodes from an asset bundle (cut to each of --levels).
//
// Usage: icd_collision_vs_fcl [--frames N] [--rounds R] [--levels L,..] [--mesh dragon|bunny|both]
//                             [--dragon-bundle DIR] [--bunny-bundle DIR]
#include <time.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fcl/fcl.h>

#include <icd/collision/sphere_update.hpp>
#include <icd/collision/traversal.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/mesh/core/error.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include "experiments/studies/collision/near_limit.hpp"
#include "experiments/studies/collision/workloads.hpp"

using namespace icd::collision;
using namespace icd::collision::experiments;
using Model = fcl::BVHModel<fcl::AABBd>;

namespace {

double now(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Wall and thread-CPU samples of one operation.
struct Samples {
  std::vector<double> wall, cpu;
  template <class F>
  void time(F&& f) {
    const double w0 = now(CLOCK_MONOTONIC), c0 = now(CLOCK_THREAD_CPUTIME_ID);
    f();
    const double c1 = now(CLOCK_THREAD_CPUTIME_ID), w1 = now(CLOCK_MONOTONIC);
    wall.push_back(w1 - w0);
    cpu.push_back(c1 - c0);
  }
  double w() const { return median(wall); }
  double c() const { return median(cpu); }
};

std::shared_ptr<Model> make_model(const icd::SurfaceMesh& m) {
  auto model = std::make_shared<Model>();
  std::vector<fcl::Triangle> tris(m.F.rows());
  for (int f = 0; f < m.F.rows(); ++f) tris[f] = fcl::Triangle(m.F(f, 0), m.F(f, 1), m.F(f, 2));
  std::vector<fcl::Vector3d> p(m.V.rows());
  for (int i = 0; i < m.V.rows(); ++i) p[i] = m.V.row(i).transpose();
  model->beginModel(static_cast<int>(m.F.rows()), static_cast<int>(m.V.rows()));
  model->addSubModel(p, tris);
  model->endModel();
  return model;
}

void refit(Model& m, const icd::MatX3d& V) {
  m.beginReplaceModel();
  for (int i = 0; i < V.rows(); ++i) m.replaceVertex(fcl::Vector3d(V(i, 0), V(i, 1), V(i, 2)));
  m.endReplaceModel(true, true);
}

// FCL's mesh-mesh query without the public call's model copies.
std::size_t fcl_query(Model& ma, Model& mb, std::size_t max_contacts) {
  fcl::CollisionRequestd req(max_contacts, false);
  fcl::CollisionResultd out;
  fcl::detail::MeshCollisionTraversalNode<fcl::AABBd> node;
  fcl::Transform3d ta = fcl::Transform3d::Identity(), tb = fcl::Transform3d::Identity();
  fcl::detail::initialize(node, ma, ta, mb, tb, req, out);
  fcl::detail::collide(&node);
  return out.numContacts();
}

bool same_spheres(const std::vector<Sphere>& x, const std::vector<Sphere>& y) {
  return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(Sphere)) == 0;
}

// An object from an asset bundle (the runner's medial-axis tree, associated
// with the coarse tet nodes), scaled and centred as load_object does (longest
// side 2), its tree cut to `levels` levels.
Object bundle_object(const icd::coupling::AssetBundle& bundle, const std::string& name,
                     const Eigen::Vector3d& center, int levels) {
  const Eigen::RowVector3d lo = bundle.dense.V.colwise().minCoeff(),
                           hi = bundle.dense.V.colwise().maxCoeff();
  const double s = 2.0 / (hi - lo).maxCoeff();
  const Eigen::RowVector3d mid = 0.5 * (lo + hi);
  auto place = [&](icd::MatX3d& V) {
    for (int i = 0; i < V.rows(); ++i) V.row(i) = (V.row(i) - mid) * s + center.transpose();
  };
  Object o;
  o.name = name;
  o.dense = bundle.dense;
  place(o.dense.V);
  o.coarse_rest = bundle.coarse.V;
  place(o.coarse_rest);
  o.tree = bundle.spheres;
  truncate_levels(o.tree, levels - 1);
  for (auto* list : {&o.tree.spheres, &o.tree.rest_spheres})
    for (Sphere& q : *list) {
      q.x = (q.x - mid.x()) * s + center.x();
      q.y = (q.y - mid.y()) * s + center.y();
      q.z = (q.z - mid.z()) * s + center.z();
      q.r *= s;
    }
  for (double& d : o.tree.assoc_rest_dist) d *= s;
  return o;
}

struct Level {
  Object a, b;
  PackedTree pa, pb;
  Samples upd, upd_nl, bound, bound_nl, trav, trav_nl;
  std::vector<double> tests, pairs;
  Level(Object a_, Object b_)
      : a(std::move(a_)), b(std::move(b_)), pa(a.tree), pb(b.tree) {}
};

// Returns the number of frames on which a near-limit loop disagreed.
int run_scene(const std::string& label, const std::string& file, const std::string& bundle_dir,
              int frames, int rounds, const std::vector<int>& levels) {
  std::vector<std::unique_ptr<Level>> lv;
  const Eigen::Vector3d ca(0, 0, 0), cb(0.45, 0.15, 0.05);
  std::string trees;
  if (bundle_dir.empty()) {
    for (int L : levels)
      lv.push_back(std::make_unique<Level>(load_object(file, ca, L), load_object(file, cb, L)));
    trees = "octree sphere trees; coarse nodes: every k-th dense vertex";
  } else {
    const icd::coupling::AssetBundle bundle = icd::coupling::read_asset_bundle(bundle_dir);
    if (bundle.spheres.num_nodes() == 0)
      throw icd::InputError("bundle " + bundle_dir + " has no sphere tree");
    for (int L : levels) {
      if (L > bundle.spheres.num_levels()) {
        std::printf("(bundle tree has %d levels: level count %d skipped)\n",
                    bundle.spheres.num_levels(), L);
        continue;
      }
      lv.push_back(std::make_unique<Level>(bundle_object(bundle, label, ca, L),
                                           bundle_object(bundle, label, cb, L)));
    }
    if (lv.empty()) throw icd::InputError("--levels: no level fits the tree of " + bundle_dir);
    trees = "medial-axis sphere trees of bundle " + bundle_dir + "; coarse nodes: its tet nodes";
  }
  const Object& a0 = lv[0]->a;
  const Object& b0 = lv[0]->b;
  std::printf("\n== %s (%s): %ld vertices, %ld triangles per copy; %ld coarse nodes; %s; %d "
              "frames x %d rounds, interleaved\n",
              label.c_str(), bundle_dir.empty() ? file.c_str() : bundle_dir.c_str(),
              (long)a0.dense.V.rows(), (long)a0.dense.F.rows(), (long)a0.coarse_rest.rows(),
              trees.c_str(), frames, rounds);
  auto ma = make_model(a0.dense), mb = make_model(b0.dense);
  fcl::CollisionObjectd oa(ma, fcl::Transform3d::Identity()), ob(mb, fcl::Transform3d::Identity());
  Samples f_refit, f_first, f_all, f_public;
  std::vector<double> contacts;
  SphereUpdateOptions paper, cons;
  cons.mode = SphereUpdateMode::DisplacementBound;
  NearLimitUpdate nlu;
  NearLimitTraversal nlt;
  CollisionResult res;
  std::vector<Sphere> outa, outb;
  int mismatches = 0;
  for (int frame = 0; frame < frames; ++frame) {
    const double t = 0.2 * frame;
    const icd::MatX3d xa = deform(a0.coarse_rest, 0.05, t), xb = deform(b0.coarse_rest, 0.05, t + 1.0);
    const icd::MatX3d Va = deform(a0.dense.V, 0.05, t), Vb = deform(b0.dense.V, 0.05, t + 1.0);
    bool frame_ok = true;
    for (int r = 0; r < rounds; ++r) {
      // Ours and the near-limit loop swap who goes first at every round
      // (counted over all frames, so that each goes first in half the runs).
      const bool ours_first = (frame * rounds + r) % 2 == 0;
      for (auto& l : lv) {
        Object &a = l->a, &b = l->b;
        outa.resize(a.tree.spheres.size());
        outb.resize(b.tree.spheres.size());
        const long nca = a.coarse_rest.rows(), ncb = b.coarse_rest.rows();
        auto upd_ours = [&](Samples& smp, const SphereUpdateOptions& o) {
          smp.time([&] {
            update_spheres(a.tree, a.coarse_rest, xa, o);
            update_spheres(b.tree, b.coarse_rest, xb, o);
          });
        };
        auto upd_nl = [&](Samples& smp, bool ratio) {
          smp.time([&] {
            nlu.run(a.tree, a.coarse_rest.data(), xa.data(), nca, ratio, outa.data());
            nlu.run(b.tree, b.coarse_rest.data(), xb.data(), ncb, ratio, outb.data());
          });
        };
        for (const bool ratio : {false, true}) {
          Samples& o = ratio ? l->upd : l->bound;
          Samples& n = ratio ? l->upd_nl : l->bound_nl;
          if (ours_first) {
            upd_ours(o, ratio ? paper : cons);
            upd_nl(n, ratio);
          } else {
            upd_nl(n, ratio);
            upd_ours(o, ratio ? paper : cons);
          }
          frame_ok &= same_spheres(outa, a.tree.spheres) && same_spheres(outb, b.tree.spheres);
        }
        auto ours = [&] { l->trav.time([&] { collide(a.tree, b.tree, CollisionRequest{}, res); }); };
        auto nl = [&] {
          l->trav_nl.time(
              [&] { nlt.run(a.tree.spheres.data(), l->pa, b.tree.spheres.data(), l->pb); });
        };
        if (ours_first) {
          ours();
          nl();
        } else {
          nl();
          ours();
        }
        frame_ok &= nlt.tests == res.tests && nlt.colliding == res.colliding && res.untested.empty();
        if (r == 0) {
          l->tests.push_back(static_cast<double>(res.tests));
          l->pairs.push_back(static_cast<double>(res.colliding.size()));
        }
      }
      f_refit.time([&] {
        refit(*ma, Va);
        refit(*mb, Vb);
        oa.computeAABB();
        ob.computeAABB();
      });
      f_first.time([&] { fcl_query(*ma, *mb, 1); });
      std::size_t n = 0;
      f_all.time([&] { n = fcl_query(*ma, *mb, 100000000); });
      if (r == 0) contacts.push_back(static_cast<double>(n));
      std::size_t np = 0;
      f_public.time([&] {
        fcl::CollisionRequestd req(100000000, false);
        fcl::CollisionResultd out;
        fcl::collide(&oa, &ob, req, out);
        np = out.numContacts();
      });
      if (np != n) {
        std::printf("  frame %d: FCL's public collide found %zu contacts, the traversal node %zu\n",
                    frame, np, n);
        frame_ok = false;
      }
    }
    if (!frame_ok) {
      ++mismatches;
      std::printf("  frame %d: a near-limit loop disagrees with the library\n", frame);
    }
  }
  std::printf("FCL, BVHModel<AABBd> over the dense triangles, both objects  wall us    cpu us\n");
  auto row = [](const char* what, const Samples& s) {
    std::printf("  %-58s %9.1f %9.1f\n", what, 1e6 * s.w(), 1e6 * s.c());
  };
  row("refit in place (replaceVertex, bottom-up) + computeAABB", f_refit);
  row("first contact (traversal node on the models, no copy)", f_first);
  row("all contacts (traversal node on the models, no copy)", f_all);
  row("all contacts, public fcl::collide (copies both models)", f_public);
  std::printf("  FCL contacts (intersecting triangle pairs), median: %.0f\n", median(contacts));
  std::printf(
      "\nours vs near-limit loop (NL) and FCL, both objects, medians; ratios of CPU times\n"
      "%-7s %-22s %9s %9s %9s %9s %8s %9s %9s\n",
      "spheres", "operation", "ours wall", "ours cpu", "NL wall", "NL cpu", "ours/NL", "FCL/ours",
      "FCL/NL");
  for (auto& l : lv) {
    const int spheres = l->a.tree.num_nodes();
    auto line = [&](const char* op, const Samples& o, const Samples& n, const Samples& f,
                    const char* fname) {
      std::printf("%-7d %-22s %9.1f %9.1f %9.1f %9.1f %8.2f %9.1f %9.1f  (FCL = %s)\n", spheres,
                  op, 1e6 * o.w(), 1e6 * o.c(), 1e6 * n.w(), 1e6 * n.c(), o.c() / n.c(),
                  f.c() / o.c(), f.c() / n.c(), fname);
    };
    line("update, paper ratio", l->upd, l->upd_nl, f_refit, "refit");
    line("update, bound", l->bound, l->bound_nl, f_refit, "refit");
    line("traversal", l->trav, l->trav_nl, f_first, "first contact");
    std::printf("%-7s %-22s %59s %9.1f %9.1f  (FCL = all contacts)\n", "", "", "",
                f_all.c() / l->trav.c(), f_all.c() / l->trav_nl.c());
    std::printf("%-7s   (%.0f sphere tests, %.0f leaf pairs, median; %d leaves per tree)\n", "",
                median(l->tests), median(l->pairs),
                l->a.tree.level_offset.back() - l->a.tree.level_offset[l->a.tree.num_levels() - 1]);
  }
  std::printf("near-limit loops identical to the library (spheres, pairs, tests) in %d of %d frames\n",
              frames - mismatches, frames);
  return mismatches;
}

constexpr const char* kProgram = "icd_collision_vs_fcl";

int run(int argc, char** argv) {
  int frames = 10, rounds = 3;
  std::string levels_text = "4,5,6", mesh = "both";
  std::filesystem::path dragon_bundle, bunny_bundle;
  icd::experiments::Cli cli(kProgram);
  cli.integer("--frames", frames, "N", "frames (default 10)", 1)
      .integer("--rounds", rounds, "R", "timed rounds per frame (default 3)", 1)
      .text("--levels", levels_text, "L,..",
            "octree sphere-tree levels, comma separated (default 4,5,6: 243, 1100, 4657 spheres "
            "per dragon)")
      .text("--mesh", mesh, "NAME", "dragon, bunny or both (default both)")
      .path("--dragon-bundle", dragon_bundle, "DIR",
            "asset bundle of the dragon: use its medial-axis tree (cut to each of --levels) and "
            "its coarse nodes instead of the octree trees")
      .path("--bunny-bundle", bunny_bundle, "DIR", "the same for the bunny");
  if (const auto status = cli.parse(argc, argv)) return *status;
  std::vector<int> levels;
  {
    std::stringstream in(levels_text);
    std::string item;
    while (std::getline(in, item, ',')) {
      char* end = nullptr;
      const long v = std::strtol(item.c_str(), &end, 10);
      if (item.empty() || *end != '\0' || v < 1 || v > 9) {
        return icd::experiments::Cli::fail(kProgram,
                                           "--levels: '" + item + "' is not a level in 1..9");
      }
      levels.push_back(static_cast<int>(v));
    }
    if (levels.empty()) {
      return icd::experiments::Cli::fail(kProgram, "--levels: no level given");
    }
  }
  if (mesh != "dragon" && mesh != "bunny" && mesh != "both") {
    return icd::experiments::Cli::fail(kProgram,
                                       "--mesh: '" + mesh + "' is not dragon, bunny or both");
  }
  std::printf("icd_collision_vs_fcl: load average at start %s (/proc/loadavg, 2 cores shared)\n",
              icd::experiments::load_average().c_str());
  int bad = 0;
  if (mesh != "bunny")
    bad += run_scene("dragon", "ChineseDragon-10kv.off", dragon_bundle.string(), frames, rounds,
                     levels);
  if (mesh != "dragon")
    bad += run_scene("bunny", "bunny00.off", bunny_bundle.string(), frames, rounds, levels);
  std::printf("\nload average at end %s\n", icd::experiments::load_average().c_str());
  if (bad > 0) {
    std::fprintf(stderr, "%s: near-limit loops disagree with the library on %d frames\n", kProgram,
                 bad);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main(kProgram, run, argc, argv);
}
