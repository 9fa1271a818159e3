#include <icd/mesh/pipeline/preprocess.hpp>

#include <chrono>
#include <ctime>
#include <sstream>
#include <utility>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/pipeline/hausdorff.hpp>

namespace icd::mesh {
namespace {

using Clock = std::chrono::steady_clock;

/// Times a stage and reports its start and end.
class StageTimer {
 public:
  StageTimer(PreprocessResult& r, const ProgressFn& progress, std::string stage)
      : m_result(r),
        m_progress(progress),
        m_stage(std::move(stage)),
        m_start(Clock::now()),
        m_cpu_start(std::clock()) {
    if (m_progress) m_progress(m_stage, "start");
  }
  void done(const std::string& message) {
    const double s = std::chrono::duration<double>(Clock::now() - m_start).count();
    const double cpu = static_cast<double>(std::clock() - m_cpu_start) / CLOCKS_PER_SEC;
    m_result.times.push_back({m_stage, s, cpu});
    if (m_progress) {
      std::ostringstream o;
      o.precision(3);
      o << message << " (" << s << " s, cpu " << cpu << " s)";
      m_progress(m_stage, o.str());
    }
  }

 private:
  PreprocessResult& m_result;
  const ProgressFn& m_progress;
  std::string m_stage;
  Clock::time_point m_start;
  std::clock_t m_cpu_start;
};

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
  {
    StageTimer t(r, progress, "repair");
    RepairResult rep = repair_surface(dense, o.repair, name);
    b.dense = std::move(rep.mesh);
    r.repair = rep.report;
    t.done(std::to_string(b.dense.V.rows()) + " vertices, " + std::to_string(b.dense.F.rows()) +
           " faces, " + std::to_string(r.repair.holes_filled) + " hole(s) filled");
  }
  r.bbox_diagonal = (b.dense.V.colwise().maxCoeff() - b.dense.V.colwise().minCoeff()).norm();
  SurfaceMesh simplified;
  {
    StageTimer t(r, progress, "simplify");
    SimplifyResult s = simplify_surface(b.dense, o.simplify);
    simplified = std::move(s.mesh);
    r.simplify = s.report;
    t.done(std::to_string(r.simplify.input_faces) + " -> " +
           std::to_string(r.simplify.output_faces) + " faces");
  }
  {
    StageTimer t(r, progress, "tetrahedralize");
    TetrahedralizeResult tet = tetrahedralize_surface(simplified, o.tetrahedralize);
    b.coarse = std::move(tet.mesh);
    r.quality = tet.quality;
    r.cell_size = tet.cell_size;
    r.mesher_passes = tet.passes;
    b.surface_nodes = boundary_nodes(b.coarse.F);
    t.done(std::to_string(b.coarse.T.rows()) + " tets, " + std::to_string(b.surface_nodes.size()) +
           " surface nodes, " + std::to_string(tet.passes) + " pass(es)");
  }
  {
    StageTimer t(r, progress, "rigid links");
    b.links = coupling::build_rigid_links(b.dense.V, b.coarse.V, b.surface_nodes, o.links);
    t.done(std::to_string(b.links.num_links()) + " links");
  }
  if (o.sphere_builder != SphereBuilder::none) {
    StageTimer t(r, progress, "sphere tree");
    if (o.sphere_builder == SphereBuilder::medial_axis) {
      SphereTreeBuild st = build_sphere_tree(b.dense, o.spheres);
      b.spheres = std::move(st.tree);
      r.sphere_time_limit_hit = st.hit_time_limit;
    } else {
      b.spheres = collision::build_octree_tree(b.dense.V, b.dense.F, o.octree);
    }
    r.sphere_levels = b.spheres.num_levels();
    const std::vector<int> cand(b.surface_nodes.data(),
                                b.surface_nodes.data() + b.surface_nodes.size());
    collision::associate_nearest_nodes(b.spheres, b.coarse.V, o.association, cand);
    t.done(std::to_string(b.spheres.num_nodes()) + " spheres on " +
           std::to_string(r.sphere_levels) + " levels" +
           (r.sphere_time_limit_hit ? " (time limit hit)" : ""));
  }
  if (o.compute_hausdorff) {
    StageTimer t(r, progress, "hausdorff");
    r.hausdorff_dense_simplified = approximate_hausdorff_distance(b.dense, simplified);
    const SurfaceMesh coarse_surface{b.coarse.V, b.coarse.F};
    r.hausdorff_dense_coarse = approximate_hausdorff_distance(b.dense, coarse_surface);
    t.done("dense-coarse " + std::to_string(r.hausdorff_dense_coarse));
  }
  return r;
}

}  // namespace icd::mesh
