#pragma once
/// Stage 3 of the preprocessing pipeline (issue 4): the coarse tetrahedral
/// mesh of a closed surface, with CGAL's 3D mesh generator (Mesh_3, polyhedral
/// domain), Delaunay refinement with quality bounds, then sliver perturbation
/// and exudation. Its boundary nodes are the reduced coordinates Q (paper 3.1).
#include <string>
#include <vector>

#include <icd/mesh/core/types.hpp>
#include <icd/mesh/pipeline/bounded.hpp>
#include <icd/mesh/pipeline/tet_cleanup.hpp>
#include <icd/mesh/pipeline/tet_quality.hpp>

namespace icd::mesh {

/// Options of tetrahedralize_surface(). The element size is cell_size when
/// > 0; otherwise it is searched so that the mesh has about target_tets tets.
struct TetrahedralizeOptions {
  int target_tets = 2000;         ///< wanted number of tets (used when cell_size == 0)
  /// Accept a size whose (unoptimised) pass gives |#tets / target - 1| <= this.
  /// The optimised pass and the stable-step post-pass then remove 5-10 % of
  /// the tets; at 0.25 most corpus meshes ended 13-22 % under the target.
  double count_tolerance = 0.12;
  int max_size_iterations = 5;    ///< meshing passes of the size search (not optimised)
  double cell_size = 0.0;  ///< upper bound of tet circumradius (model units); 0: from target_tets
  double facet_size_factor = 1.0;      ///< facet size = factor * cell size
  /// Circumradius bound of the cells = factor * cell size: below 1 the
  /// interior is refined more than the surface (more interior nodes, for the
  /// same tet count a coarser surface).
  double interior_size_factor = 1.0;
  double facet_distance_factor = 0.1;  ///< facet distance bound = factor * cell size
  double facet_angle_deg = 25.0;       ///< lower bound of surface triangle angles (<= 30)
  double radius_edge_bound = 3.0;  ///< cell radius-edge ratio bound (>= 2 guarantees termination)
  bool perturb = true;             ///< CGAL perturb_mesh_3 against slivers
  bool exude = true;               ///< CGAL exude_mesh_3 against slivers
  /// Dihedral angle (deg) targeted by perturb/exude: 12 meets the minimum
  /// dihedral target of explicit FEM on the bunny at 4 s CPU (15: 17 s; 10: 1.3 s).
  double sliver_bound_deg = 12.0;
  /// Edges whose faces meet at more than this angle (deg, between normals)
  /// are sharp features, protected (Mesh_3 polyhedral domain with features):
  /// kept in the coarse surface and the refinement terminates near them.
  /// 0: no feature detection (the default: measured on the corpus, protection
  /// gave worse tets and more failed passes with this seeding, see
  /// experiments/studies/preprocess/README.md).
  double feature_angle_deg = 0.0;
  /// After the optimised pass: collapse the nodes that limit the explicit
  /// FEM stable step (tet_cleanup.hpp; target_ratio 0 turns it off).
  StepCleanupOptions step_cleanup;
  unsigned random_seed = 0;        ///< CGAL default random generator seed (determinism)
  /// CPU-time and memory limits of the whole stage; each meshing pass runs
  /// bounded (bounded.hpp) by at most pass_share of the CPU time, so that a
  /// pass that stalls leaves time for the retries.
  StageLimits limits;
  double pass_share = 0.34;  ///< in (0, 1]
  /// CPU seconds all passes of this call may use together (0: limits.cpu_seconds).
  /// Each pass still gets at most pass_share x limits.cpu_seconds. The
  /// preprocessing's automatic wrap retry splits one --time-limit between the
  /// first attempt and the retry with it.
  double cpu_budget = 0.0;
  /// Passes that fail (no tet, a non-manifold boundary, a CGAL failure, a pass
  /// limit) are retried at nearby cell sizes (x 0.85, 1.15, 0.7, 1.3, ...) up
  /// to this many times in all; each retry is reported in the result's notes.
  int max_retries = 6;
  /// Deterministic stall guard: a refinement pass stops (and fails) at this
  /// many times the vertices its size should give (regular tets of that size
  /// filling the volume plus the surface's triangles; at least
  /// min_vertex_cap). Runaway refinement (surfaces closer to each other than
  /// the cell size: near-contact gaps, thin sheets) ran passes for minutes
  /// into their CPU limit; with the cap it fails in seconds, and such a pass
  /// is retried at most once, at a coarser size. 0: no cap.
  double over_refinement_factor = 20.0;
  int min_vertex_cap = 20000;
  /// The surface is already an alpha wrap (repair's or the automatic wrap
  /// retry's): a refusal names --wrap-alpha instead of --wrap always.
  bool wrapped_surface = false;
  /// The repair's --wrap-alpha (fraction of the diagonal; 0: unknown): a
  /// refusal after every pass over-refined suggests a wrap at 10 x it.
  double wrap_alpha = 0.0;
};

/// Result of tetrahedralize_surface().
struct TetrahedralizeResult {
  TetMesh mesh;  ///< positive tets, outward boundary F, every vertex used
  TetQuality quality;
  double cell_size = 0;  ///< cell size of the pass that was kept
  int passes = 0;        ///< meshing passes run (size search + the final optimised one)
  int feature_curves = 0;  ///< sharp-feature polylines protected
  int failed_passes = 0;  ///< passes that failed and were retried at another size
  int over_refined_passes = 0;  ///< of them, passes stopped by the vertex cap
  StepCleanupReport step_cleanup;  ///< of the kept (optimised) pass
  /// One line per retry or notable event ("pass 2 at cell size 0.03 failed:
  /// ...; retrying at 0.0255").
  std::vector<std::string> notes;
  StageUsage usage;  ///< summed over the passes (peak: the largest)
};

/// The cell size tetrahedralize_surface() tries first when options.cell_size
/// is 0, for a surface enclosing `volume` and target_tets tets: twice the
/// circumradius of regular tets of that mean volume (refinement stops well
/// below the bound).
double initial_cell_size(double volume, int target_tets);

/// Tetrahedralizes the region bounded by `surface` (closed, outward-oriented,
/// no self-intersection: the output of repair_surface()/simplify_surface()).
/// Deterministic: CGAL's default random generator is reset to random_seed
/// before each pass and the meshing runs sequentially (only a limit that
/// fires makes the result depend on timing; it is reported in notes).
/// Throws ParameterError on bad options, InputError when the surface is not
/// closed, and StageError/InputError when every retry failed (no tet, a tet
/// boundary that is not a closed manifold surface, a limit): the message
/// names the cause of each failed pass and the options to change.
/// `heartbeat` (optional) receives progress lines.
TetrahedralizeResult tetrahedralize_surface(const SurfaceMesh& surface,
                                            const TetrahedralizeOptions& options = {},
                                            const HeartbeatFn& heartbeat = {});

}  // namespace icd::mesh
