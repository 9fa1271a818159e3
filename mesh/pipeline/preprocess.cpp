#include <icd/mesh/pipeline/preprocess.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/mesh_stats.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/pipeline/canonical.hpp>
#include <icd/mesh/pipeline/hausdorff.hpp>
#include <icd/mesh/pipeline/near_contact.hpp>

namespace icd::mesh {
namespace {

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}

/// Runs one stage bounded, reports start, progress and end, records its usage.
class Stage {
 public:
  Stage(PreprocessResult& r, const ProgressFn& progress, std::string name)
      : m_result(r), m_progress(progress), m_name(std::move(name)) {
    if (m_progress) m_progress(m_name, "start");
  }
  HeartbeatFn heartbeat() const {
    if (!m_progress) return {};
    return [this](const std::string& s) { m_progress(m_name, s); };
  }
  std::string run(const StageLimits& limits, const std::function<std::string()>& work,
                  const std::string& hint = "") {
    return run_bounded(m_name, limits, work, &m_usage, heartbeat(), hint);
  }
  void set_usage(const StageUsage& u) { m_usage = u; }
  const StageUsage& usage() const { return m_usage; }
  void done(const std::string& message) {
    m_result.times.push_back({m_name, m_usage.wall_seconds, m_usage.cpu_seconds, m_usage.peak_mb});
    if (m_progress) {
      std::ostringstream o;
      o.precision(3);
      o << message << " (" << m_usage.wall_seconds << " s, cpu " << m_usage.cpu_seconds << " s, "
        << std::lround(m_usage.peak_mb) << " MB)";
      m_progress(m_name, o.str());
    }
  }

 private:
  PreprocessResult& m_result;
  const ProgressFn& m_progress;
  std::string m_name;
  StageUsage m_usage;
};

void write_surface(ByteWriter& w, const SurfaceMesh& m) {
  w.mat(m.V);
  w.mat(m.F);
}
SurfaceMesh read_surface(ByteReader& r) {
  SurfaceMesh m;
  m.V = r.mat<MatX3d>();
  m.F = r.mat<MatX3i>();
  return m;
}

void write_tree(ByteWriter& w, const collision::SphereTree& t) {
  w.vec(t.spheres);
  w.vec(t.rest_spheres);
  w.vec(t.first_child);
  w.vec(t.child_count);
  w.vec(t.level);
  w.vec(t.level_offset);
  w.vec(t.assoc_offset);
  w.vec(t.assoc_nodes);
  w.vec(t.assoc_rest_dist);
}
collision::SphereTree read_tree(ByteReader& r) {
  collision::SphereTree t;
  t.spheres = r.vec<collision::Sphere>();
  t.rest_spheres = r.vec<collision::Sphere>();
  t.first_child = r.vec<int32_t>();
  t.child_count = r.vec<int32_t>();
  t.level = r.vec<int32_t>();
  t.level_offset = r.vec<int32_t>();
  t.assoc_offset = r.vec<int32_t>();
  t.assoc_nodes = r.vec<int32_t>();
  t.assoc_rest_dist = r.vec<double>();
  return t;
}

Normalisation normalisation_of(const MatX3d& V) {
  Normalisation n;
  if (V.rows() == 0 || !V.allFinite()) return n;  // repair refuses it, naming the vertex
  const Eigen::RowVector3d lo = V.colwise().minCoeff(), hi = V.colwise().maxCoeff();
  const double diagonal = (hi - lo).norm();
  if (!(diagonal > 0.0) || !std::isfinite(diagonal)) return n;
  const Eigen::RowVector3d centre = 0.5 * (lo + hi);
  if (centre.norm() > 4.0 * diagonal) n.centre = centre;
  n.scale = std::ldexp(1.0, -std::ilogb(diagonal));  // diagonal * scale in [1, 2)
  return n;
}

void to_model(MatX3d& V, const Normalisation& n) {
  V /= n.scale;  // exact: a power of two
  if (!n.centre.isZero()) V.rowwise() += n.centre;
}

void sphere_to_model(collision::Sphere& s, const Normalisation& n) {
  s.x = s.x / n.scale + n.centre[0];
  s.y = s.y / n.scale + n.centre[1];
  s.z = s.z / n.scale + n.centre[2];
  s.r /= n.scale;
}

}  // namespace

SphereFit parse_sphere_fit(const std::string& name, const std::string& field) {
  for (SphereFit fit : {SphereFit::light, SphereFit::full, SphereFit::shell})
    if (name == to_string(fit)) return fit;
  throw ParameterError(field + ": must be light, full or shell, got '" + name + "'");
}

const char* to_string(SphereFit fit) {
  switch (fit) {
    case SphereFit::light:
      return "light";
    case SphereFit::full:
      return "full";
    case SphereFit::shell:
      return "shell";
  }
  return "?";
}

void apply_sphere_fit(SphereFit fit, SphereTreeOptions& spheres) {
  SphereTreeOptions o;
  o.depth = spheres.depth;
  o.branching = spheres.branching;
  o.max_spheres_per_level = spheres.max_spheres_per_level;
  o.threads = spheres.threads;
  o.time_limit = spheres.time_limit;
  switch (fit) {
    case SphereFit::light:
      o.reduction.lloyd_iterations = 1;
      o.sampling.refinement_iterations = 0;
      o.sampling.medial_spacing = 1.0 / 80.0;
      o.sampling.cover_spacing = 1.0 / 400.0;
      break;
    case SphereFit::full:
      break;
    case SphereFit::shell:
      o.reduction.joint_leaf_refinement = true;
      o.allocation.regroup_parents = true;
      o.allocation.worst_share = 1;
      o.allocation.leaf_worst_target = 0;
      o.allocation.leaf_worst_factor = 0;
      break;
  }
  spheres = std::move(o);
}

PreprocessResult preprocess(const SurfaceMesh& dense, const PreprocessOptions& o,
                            const ProgressFn& progress, const std::string& name) {
  PreprocessResult r;
  coupling::AssetBundle& b = r.bundle;
  const StageLimits& limits = o.limits;
  const Normalisation norm = normalisation_of(dense.V);
  r.normalisation = norm;
  const double s = norm.scale, s3 = s * s * s;
  SurfaceMesh input = dense;
  if (!norm.centre.isZero()) input.V.rowwise() -= norm.centre;
  input.V *= s;
  // Stages 1 and 2, repeated by the wrap retry below: the repaired surface
  // (b.dense, r.repair, in the input's order) and its canonical order and
  // simplification.
  const auto repair_once = [&](const RepairOptions& ro, StageUsage* usage,
                               const HeartbeatFn& beat, const StageLimits& lim) {
    ByteReader in(run_bounded(
        "repair", lim,
        [&] {
          RepairResult rep = repair_surface(input, ro, name);
          ByteWriter w;
          write_surface(w, rep.mesh);
          w.pod(rep.report);
          return w.take();
        },
        usage, beat));
    b.dense = read_surface(in);
    r.repair = in.pod<RepairReport>();
    r.bbox_diagonal = (b.dense.V.colwise().maxCoeff() - b.dense.V.colwise().minCoeff()).norm();
  };
  SurfaceMesh canonical, simplified;
  const auto simplify_once = [&](StageUsage* usage, const HeartbeatFn& beat,
                                 const StageLimits& lim) {
    // The stages below see the repaired surface in an order fixed by its
    // geometry (canonical.hpp): permuted input gives the same coarse mesh and
    // sphere tree. The bundle keeps the repaired surface in the input's order.
    canonical = canonical_order(b.dense);
    ByteReader in(run_bounded(
        "simplify", lim,
        [&] {
          SimplifyResult sr = simplify_surface(canonical, o.simplify);
          ByteWriter w;
          write_surface(w, sr.mesh);
          w.pod(sr.report);
          return w.take();
        },
        usage, beat));
    simplified = read_surface(in);
    r.simplify = in.pod<SimplifyReport>();
  };
  {
    Stage t(r, progress, "repair");
    StageUsage u;
    repair_once(o.repair, &u, t.heartbeat(), limits);
    t.set_usage(u);
    t.done(std::to_string(b.dense.V.rows()) + " vertices, " + std::to_string(b.dense.F.rows()) +
           " faces, " + std::to_string(r.repair.holes_filled) + " hole(s) filled");
  }
  {
    Stage t(r, progress, "simplify");
    StageUsage u;
    simplify_once(&u, t.heartbeat(), limits);
    t.set_usage(u);
    t.done(std::to_string(r.simplify.input_faces) + " -> " +
           std::to_string(r.simplify.output_faces) + " faces");
  }
  {
    Stage t(r, progress, "tetrahedralize");
    TetrahedralizeOptions to = o.tetrahedralize;
    to.limits = limits;
    to.cell_size *= s;
    to.wrapped_surface = r.repair.wrap_cause != 0;
    to.wrap_alpha = o.repair.wrap_alpha;
    const bool retry_possible =
        o.repair.wrap == RepairOptions::Wrap::fallback && r.repair.wrap_cause == 0;
    if (!(o.wrap_retry_first_share > 0.0 && o.wrap_retry_first_share <= 1.0))
      throw ParameterError("preprocess: wrap_retry_first_share must be in (0, 1]");
    // One CPU budget for the stage: the first attempt leaves the rest of it
    // to the wrap retry (a pass that would run past the share fails as it
    // would at the limit).
    if (retry_possible) to.cpu_budget = o.wrap_retry_first_share * limits.cpu_seconds;
    TetrahedralizeResult tet;
    // The passes run in child processes: a failed attempt's CPU time is the
    // children's, which the retry adds to this stage's.
    const auto children_cpu = [] {
      rusage ru{};
      getrusage(RUSAGE_CHILDREN, &ru);
      return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
             1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    };
    const double cpu0 = children_cpu();
    const auto wall0 = std::chrono::steady_clock::now();
    // The first cell size, and the parts in near contact: distinct
    // components closer than the mesher's surface tolerance (the facet
    // distance bound at that size) over more than a point make every pass
    // refine between them up to its vertex cap (bones: 26 bones 0.1 % of the
    // diagonal apart), so the first attempt is skipped for the wrap retry
    // below.
    double first_size = to.cell_size, tolerance = 0.0;
    ComponentGap gap;
    StageUsage check;
    if (retry_possible) {
      const bool check_gap = o.wrap_near_contact;
      ByteReader in(run_bounded(
          "tetrahedralize", limits,
          [&] {
            const double size =
                to.cell_size > 0.0
                    ? to.cell_size
                    : initial_cell_size(compute_surface_stats(simplified).volume, to.target_tets);
            ByteWriter w;
            w.pod(size);
            w.pod(check_gap ? closest_component_gap(simplified, to.facet_distance_factor * size)
                            : ComponentGap{});
            return w.take();
          },
          &check));
      first_size = in.pod<double>();
      gap = in.pod<ComponentGap>();
      tolerance = to.facet_distance_factor * first_size;
    }
    // More than a contact at one point (2-3 vertices: the fans of a split
    // non-manifold vertex, which the mesher resolves).
    const bool near_contact = gap.distance < tolerance && gap.close_vertices >= 4;
    try {
      if (near_contact) {
        std::ostringstream m;
        m << "components " << gap.first + 1 << " and " << gap.second + 1 << " of its "
          << gap.components << " lie " << fmt(gap.distance / s) << " apart ("
          << fmt(100.0 * gap.distance / r.bbox_diagonal) << " % of the diagonal) near ("
          << fmt(gap.where[0] / s + norm.centre[0]) << ", "
          << fmt(gap.where[1] / s + norm.centre[1]) << ", "
          << fmt(gap.where[2] / s + norm.centre[2])
          << "), " << gap.close_vertices << " vertices closer to another part than the mesher's "
          << "surface tolerance " << fmt(tolerance / s) << " (" << fmt(to.facet_distance_factor)
          << " x the first cell size " << fmt(first_size / s)
          << "): every pass would refine between them up to its vertex cap";
        throw InputError(m.str());
      }
      tet = tetrahedralize_surface(simplified, to, t.heartbeat());
      tet.usage.cpu_seconds += check.cpu_seconds;
      tet.usage.wall_seconds += check.wall_seconds;
    } catch (const ParameterError&) {
      throw;
    } catch (const InputError& e) {
      // Automatic wrap retry: the mesher failed at every size on a repaired
      // (not wrapped) surface, typically surfaces closer to each other than
      // the cell size (near-contact gaps between parts: bones, camel). Mesh
      // the alpha wrap of the input once instead (it closes gaps narrower
      // than alpha), repeating repair and simplification, all counted in this
      // stage; the summary's repair section and notes say so.
      if (!retry_possible) throw;
      std::string first = e.what();
      // The retry is the option: the first attempt's cause without its options.
      first = first.substr(0, std::min(first.find(". Options that change this"),
                                       first.find(". Cause: every pass over-refined")));
      const double first_cpu = children_cpu() - cpu0;
      const double first_wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
      const HeartbeatFn beat = t.heartbeat();
      if (beat)
        beat(near_contact ? "parts of the repaired surface in near contact (" + first +
                                "); meshing its alpha wrap at once (--wrap never refuses instead)"
                          : "the mesher failed on the repaired surface at every size; retrying "
                            "once on its alpha wrap (--wrap never refuses instead)");
      RepairOptions ro = o.repair;
      ro.wrap = RepairOptions::Wrap::always;
      // Parts in near contact: the wrap joins them into one solid. It closes
      // straits narrower than 2 alpha, so alpha half the first cell size
      // closes the gaps between them that no cell can resolve (the default
      // 0.01 of the diagonal left bones' 1-5 % gaps open, and a pass refined
      // between them into its CPU limit). The user's --wrap-alpha is the
      // floor; a wrap that lies too far from the input is redone at a smaller
      // alpha (below). (Not
      // after a failed first attempt: camel's retry meshes at 0.01 and a
      // larger alpha webs its legs: 0.94 -> 2.48 % of the diagonal from the
      // input.)
      if (near_contact)
        ro.wrap_alpha = std::max(o.repair.wrap_alpha, 0.5 * first_size / r.bbox_diagonal);
      std::string alpha_note;
      StageUsage ru, su;
      try {
        // What is left of the stage's CPU limit bounds the retry's repair and
        // simplification, then its passes together.
        const auto left = [&] {
          return limits.cpu_seconds - (children_cpu() - cpu0);
        };
        const auto require = [&](double seconds) {
          if (seconds < 0.5)
            throw InputError("the stage's CPU-time limit of " + fmt(limits.cpu_seconds) +
                             " s (--time-limit) is used up");
        };
        StageLimits rl = limits;
        rl.cpu_seconds = left();
        require(rl.cpu_seconds);
        // A wrap refused (too far from the input) is redone at 0.75 x its
        // alpha, down to --wrap-alpha (refused there: the refusal stands).
        std::string refused;
        const double scaled = ro.wrap_alpha;
        for (;;) {
          StageUsage u;
          try {
            repair_once(ro, &u, beat, rl);
          } catch (const ParameterError&) {
            throw;
          } catch (const InputError& w) {
            ru += u;
            if (!(ro.wrap_alpha > o.repair.wrap_alpha)) throw;
            refused += (refused.empty() ? "" : ", ") + fmt(ro.wrap_alpha);
            if (beat)
              beat("the wrap at alpha " + fmt(ro.wrap_alpha) + " was refused: " + w.what());
            ro.wrap_alpha = std::max(o.repair.wrap_alpha, 0.75 * ro.wrap_alpha);
            rl.cpu_seconds = left();
            require(rl.cpu_seconds);
            continue;
          }
          ru += u;
          break;
        }
        if (scaled > o.repair.wrap_alpha)
          alpha_note = "alpha " + fmt(ro.wrap_alpha) + " of the diagonal: half the first cell " +
                       "size " + fmt(first_size / s) +
                       " so that gaps narrower than a cell are closed" +
                       (refused.empty() ? ""
                                        : ", or less: the wraps at alpha " + refused +
                                              " were refused (too far from the input)") +
                       "; --wrap-alpha " + fmt(o.repair.wrap_alpha) + " is the floor";
        rl.cpu_seconds = left();
        require(rl.cpu_seconds);
        simplify_once(&su, beat, rl);
        to.wrapped_surface = true;
        to.cpu_budget = left();
        require(to.cpu_budget);
        tet = tetrahedralize_surface(simplified, to, beat);
      } catch (const ParameterError&) {
        throw;
      } catch (const InputError& e2) {
        throw InputError(std::string(e2.what()) +
                         " [after the automatic retry on the alpha-wrapped surface" +
                         (alpha_note.empty() ? "" : " (" + alpha_note + ")") +
                         "; on the repaired surface first: " + first + "]");
      }
      r.repair.wrap_cause = near_contact ? 5 : 4;
      tet.usage.cpu_seconds += first_cpu + ru.cpu_seconds + su.cpu_seconds;
      tet.usage.wall_seconds += first_wall + ru.wall_seconds + su.wall_seconds;
      tet.usage.peak_mb = std::max({tet.usage.peak_mb, ru.peak_mb, su.peak_mb});
      r.wrap_retry_cause = first;
      if (near_contact)
        r.notes.push_back("tetrahedralize: parts of the repaired surface in near contact (" +
                          first + "); the mesher was not run on it: the surface was rebuilt by "
                          "alpha wrapping" + (alpha_note.empty() ? "" : " (" + alpha_note + ")") +
                          " and meshed at once (in this stage's time and CPU limit; --wrap never "
                          "refuses instead)");
      else
        r.notes.push_back("tetrahedralize: the mesher failed on the repaired surface at every "
                          "size (" + first + "; " + fmt(first_cpu) + " s CPU); the surface was "
                          "rebuilt by alpha wrapping and meshed once more (both attempts, with "
                          "the second repair and simplification, in this stage's time and its "
                          "one CPU limit; --wrap never refuses instead)");
    }
    t.set_usage(tet.usage);
    b.coarse = std::move(tet.mesh);
    r.quality = tet.quality;
    r.cell_size = tet.cell_size / s;
    r.mesher_passes = tet.passes;
    for (const std::string& n : tet.notes) r.notes.push_back("tetrahedralize: " + n);
    if (tet.step_cleanup.ratio_before > 0) {
      char buf[480];
      const StepCleanupReport& c = tet.step_cleanup;
      std::snprintf(buf, sizeof buf,
                    "tetrahedralize: stable-step post-pass collapsed %d node(s) (node estimate of "
                    "the step ratio %.3f -> %.3f, volume %+.2f %%, %d node(s) left above the "
                    "target; --step-target); dihedral phase: %d collapse(s), %d flip(s), %d "
                    "surface sliver(s) dropped, %d relocation(s), %d off the surface, smallest "
                    "angle %.2f -> %.2f deg",
                    c.collapses, c.ratio_before, c.ratio_after, 100.0 * c.volume_change, c.stuck,
                    c.dihedral_collapses, c.flips, c.drops, c.relocations, c.off_surface,
                    c.min_dihedral_before,
                    c.min_dihedral_after);
      r.notes.push_back(buf);
    }
    b.surface_nodes = boundary_nodes(b.coarse.F);
    t.done(std::to_string(b.coarse.T.rows()) + " tets, " + std::to_string(b.surface_nodes.size()) +
           " surface nodes, " + std::to_string(tet.passes) + " pass(es)" +
           (tet.failed_passes ? ", " + std::to_string(tet.failed_passes) + " failed and retried"
                              : ""));
  }
  {
    Stage t(r, progress, "rigid links");
    ByteReader in(t.run(limits, [&] {
      const coupling::RigidLinks l =
          coupling::build_rigid_links(b.dense.V, b.coarse.V, b.surface_nodes, o.links);
      ByteWriter w;
      w.mat(l.nodes);
      w.mat(l.alpha);
      w.mat(l.coeffs);
      w.pod(l.num_coarse_nodes);
      return w.take();
    }));
    b.links.nodes = in.mat<coupling::MatX3i32>();
    b.links.alpha = in.mat<MatX3d>();
    b.links.coeffs = in.mat<MatX3d>();
    b.links.num_coarse_nodes = in.pod<int32_t>();
    t.done(std::to_string(b.links.num_links()) + " links");
  }
  if (o.sphere_builder != SphereBuilder::none) {
    Stage t(r, progress, "sphere tree");
    const auto build = [&](SphereBuilder builder) {
      return [&, builder] {
        collision::SphereTree tree;
        bool hit = false;
        if (builder == SphereBuilder::medial_axis) {
          SphereTreeBuild st = build_sphere_tree(canonical, o.spheres);
          tree = std::move(st.tree);
          hit = st.hit_time_limit;
        } else {
          tree = collision::build_octree_tree(canonical.V, canonical.F, o.octree);
        }
        const std::vector<int> cand(b.surface_nodes.data(),
                                    b.surface_nodes.data() + b.surface_nodes.size());
        collision::associate_nearest_nodes(tree, b.coarse.V, o.association, cand);
        ByteWriter w;
        write_tree(w, tree);
        w.pod(hit);
        return w.take();
      };
    };
    std::string bytes;
    try {
      bytes = t.run(limits, build(o.sphere_builder),
                    "--spheres octree builds a coarser tree much faster");
    } catch (const StageError& e) {
      // The medial-axis builder beyond its limits: the octree builder
      // instead (seconds, deterministic), with a WARNING in the summary.
      if (o.sphere_builder != SphereBuilder::medial_axis ||
          (e.kind() != StageError::Kind::cpu_limit && e.kind() != StageError::Kind::memory_limit))
        throw;
      const StageUsage first = t.usage();
      if (const HeartbeatFn beat = t.heartbeat())
        beat("the medial-axis builder went beyond the stage's limits; building the octree tree "
             "instead");
      bytes = t.run(limits, build(SphereBuilder::octree));
      StageUsage sum = t.usage();
      sum += first;
      t.set_usage(sum);
      r.sphere_fallback = std::string(e.what()) + " (" + fmt(first.cpu_seconds) + " s CPU)";
      r.notes.push_back("WARNING: sphere tree: " + r.sphere_fallback +
                        "; the bundle holds the octree builder's tree instead (coarser: more "
                        "sphere tests near contact; a larger --time-limit builds the medial tree)");
    }
    ByteReader in(std::move(bytes));
    b.spheres = read_tree(in);
    r.sphere_time_limit_hit = in.pod<bool>();
    r.sphere_levels = b.spheres.num_levels();
    t.done(std::to_string(b.spheres.num_nodes()) + " spheres on " +
           std::to_string(r.sphere_levels) + " levels" +
           (r.sphere_time_limit_hit ? " (time limit hit)" : ""));
  }
  if (o.compute_hausdorff) {
    Stage t(r, progress, "hausdorff");
    ByteReader in(t.run(
        limits,
        [&] {
          ByteWriter w;
          w.pod(approximate_hausdorff_distance(b.dense, simplified));
          const SurfaceMesh coarse_surface{b.coarse.V, b.coarse.F};
          w.pod(approximate_hausdorff_distance(b.dense, coarse_surface));
          return w.take();
        },
        "--no-hausdorff skips it"));
    r.hausdorff_dense_simplified = in.pod<double>() / s;
    r.hausdorff_dense_coarse = in.pod<double>() / s;
    t.done("dense-coarse " + fmt(r.hausdorff_dense_coarse));
  }

  // Back to model units.
  to_model(b.dense.V, norm);
  to_model(b.coarse.V, norm);
  b.links.coeffs /= s;
  for (auto& sp : b.spheres.spheres) sphere_to_model(sp, norm);
  for (auto& sp : b.spheres.rest_spheres) sphere_to_model(sp, norm);
  for (double& d : b.spheres.assoc_rest_dist) d /= s;
  r.bbox_diagonal /= s;
  r.repair.volume /= s3;
  r.repair.input_volume /= s3;
  r.quality = tet_quality(b.coarse);
  r.stable_step = stable_step_report(b.coarse, o.stable_step);
  return r;
}

}  // namespace icd::mesh
