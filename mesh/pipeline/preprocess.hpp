#pragma once
/// The whole off-line preparation of one deformable object (issue 4; paper
/// sections 3.1, 4.4 and 5): repair -> simplify -> tetrahedralize -> rigid
/// links -> sphere tree and sphere-to-node association, producing the asset
/// bundle the simulator loads.
#include <functional>
#include <string>
#include <vector>

#include <icd/collision/node_association.hpp>
#include <icd/collision/octree_tree.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/coupling/rigid_links.hpp>
#include <icd/mesh/core/types.hpp>
#include <icd/mesh/pipeline/bounded.hpp>
#include <icd/mesh/pipeline/fem_step.hpp>
#include <icd/mesh/pipeline/repair.hpp>
#include <icd/mesh/pipeline/simplify.hpp>
#include <icd/mesh/pipeline/tetrahedralize.hpp>
#include <icd/mesh/spheres/builder.hpp>

namespace icd::mesh {

/// Which sphere-tree builder the sphere stage runs.
enum class SphereBuilder {
  medial_axis,  ///< mesh/spheres build_sphere_tree (adaptive medial axis, paper 4.1)
  octree,       ///< collision/octree_tree build_octree_tree (fast baseline)
  none,         ///< no sphere tree in the bundle
};

/// How far the medial-axis sphere tree is optimised (icd-preprocess
/// --sphere-fit, scene field preprocess.tree_fit). Measured against light
/// (icd-preprocess defaults otherwise, 400 approach poses of
/// contact_tightness; experiments/studies/preprocess/README.md, "Sphere-tree
/// fit"), dragon / bunny: full -12 % / +10 % false leaf pairs near
/// contact, -5 % / +28 % sphere tests; shell -15 % / +3 %, +26 % / +21 %.
/// No fit is better on both models, so light stays the default.
enum class SphereFit {
  /// One Lloyd round, no adaptive refinement, finer medial and coarser
  /// coverage samples: the preprocessing's default.
  light,
  /// The builder's defaults (the issue-5 table's trees there have caps of
  /// 1/8/64/445 spheres per level; here every level may fill up).
  full,
  /// full with the joint leaf pass, worst-first allocation and the parents
  /// regrouped: the thinnest leaf shell, a thicker level 2.
  shell,
};

/// "light", "full" or "shell"; anything else throws ParameterError naming
/// `field` and the choices.
SphereFit parse_sphere_fit(const std::string& name, const std::string& field = "sphere fit");
const char* to_string(SphereFit fit);

/// Sets the fitting options of `spheres` for `fit`, keeping the tree's shape
/// (depth, branching, per-level caps), its thread count and its time limit.
void apply_sphere_fit(SphereFit fit, SphereTreeOptions& spheres);

/// Options of every stage; the defaults are the tool's defaults.
struct PreprocessOptions {
  RepairOptions repair;
  SimplifyOptions simplify;
  TetrahedralizeOptions tetrahedralize;
  coupling::RigidLinkOptions links;
  SphereBuilder sphere_builder = SphereBuilder::medial_axis;
  /// Medial-axis builder options: SphereFit::light, and no time limit (a
  /// limit of CPU seconds that fires makes the output depend on timing: not
  /// byte-reproducible).
  SphereTreeOptions spheres;
  collision::OctreeTreeOptions octree;  ///< octree builder options (levels = depth + 1)
  collision::NodeAssociationOptions association;
  bool compute_hausdorff = true;  ///< dense vs coarse surface distance for the summary
  /// Material, damping and integrator of the stable-step figure of the
  /// summary (a scene object's defaults).
  StableStepOptions stable_step;
  /// CPU-time and memory limits of every stage (each runs in a child
  /// process, bounded.hpp); tetrahedralize.limits is set from it.
  StageLimits limits;
  /// The tetrahedralize stage has one CPU budget, limits.cpu_seconds, for
  /// both attempts of the automatic wrap retry: the first attempt (on the
  /// repaired surface, when a retry may follow) may use this share of it, the
  /// retry (the wrap's repair, simplification and meshing) what is left.
  /// Each mesher pass keeps its own bound (TetrahedralizeOptions::pass_share
  /// of the limit). In (0, 1].
  double wrap_retry_first_share = 0.5;
  /// When the automatic wrap retry may follow and two distinct components of
  /// the repaired surface lie closer than the mesher's surface tolerance (the
  /// facet distance bound at the first cell size), skip the first attempt,
  /// which would refine between them up to its vertex cap at every size, and
  /// mesh the alpha wrap at once (repair.wrap_cause 5, a note naming the two
  /// components, their gap and where). false: the first attempt runs and fails.
  bool wrap_near_contact = true;
  PreprocessOptions() {
    spheres.time_limit = 1e9;
    apply_sphere_fit(SphereFit::light, spheres);
    octree.levels = spheres.depth + 1;
  }
};

/// Time of one stage (seconds): wall clock and process CPU time (the machine
/// may be shared; CPU time is the load-independent figure).
struct StageTime {
  std::string stage;
  double seconds = 0.0;
  double cpu_seconds = 0.0;
  double peak_mb = 0.0;  ///< peak resident memory of the stage's process (MiB)
};

/// The similarity that maps the input to normalised coordinates, in which
/// every stage works: x_n = (x - centre) * scale, scale a power of two (exact)
/// with the bounding-box diagonal in [1, 2); centre the bounding-box centre
/// when the model lies far from the origin (farther than 4 diagonals), else 0,
/// so that the round trip is exact and the dense vertices keep their bits.
struct Normalisation {
  Eigen::RowVector3d centre = Eigen::RowVector3d::Zero();
  double scale = 1.0;
};

/// Everything preprocess() produced and measured.
struct PreprocessResult {
  coupling::AssetBundle bundle;  ///< dense = repaired input surface
  RepairReport repair;
  SimplifyReport simplify;
  TetQuality quality;      ///< of bundle.coarse
  /// Stable step of bundle.coarse (model units as metres) against near-regular
  /// tets of the same mean volume (fem_step.hpp).
  StableStepReport stable_step;
  double cell_size = 0.0;  ///< Mesh_3 cell size that was kept
  int mesher_passes = 0;
  int sphere_levels = 0;
  bool sphere_time_limit_hit = false;  ///< the builder stopped early: output may vary between runs
  /// Non-empty when the medial-axis builder exceeded the stage's CPU or
  /// memory limit and the bundle holds the octree builder's tree instead:
  /// the limit's message.
  std::string sphere_fallback;
  /// Approximate symmetric Hausdorff distances (model units; -1 when not computed):
  double hausdorff_dense_simplified = -1.0;  ///< repaired dense vs simplified surface
  double hausdorff_dense_coarse = -1.0;      ///< repaired dense vs coarse tet boundary
  double bbox_diagonal = 0.0;                ///< of the repaired dense surface
  std::vector<StageTime> times;              ///< in stage order
  Normalisation normalisation;               ///< the stages' coordinates
  /// Why the mesher failed on the repaired surface (repair.wrap_cause 4), or
  /// which parts lie in near contact (5), when the automatic wrap retry
  /// meshed its alpha wrap instead; else empty.
  std::string wrap_retry_cause;
  /// Retries and warnings of every stage, for the summary (one line each).
  std::vector<std::string> notes;
};

/// Progress report: the stage name and a short message (start, pass, done).
using ProgressFn = std::function<void(const std::string& stage, const std::string& message)>;

/// Runs all stages on `dense` (a raw surface as read from file; `name` prefixes
/// error messages), in normalised coordinates (Normalisation; the bundle and
/// every figure of the result are in model units). With the default
/// RepairOptions::Wrap::fallback, a repaired (not wrapped) surface on which
/// the mesher fails at every size is rebuilt by alpha wrapping and meshed
/// once more (the automatic wrap retry; repair.wrap_cause 4, a note, its CPU
/// in the tetrahedralize stage, both attempts within the stage's one CPU
/// limit: wrap_retry_first_share); distinct parts closer than the mesher's
/// surface tolerance are wrapped at once (wrap_near_contact), at an alpha of
/// half the first cell size (as a fraction of the diagonal; at least
/// repair.wrap_alpha, which it falls back to when that wrap is refused), so
/// that the gaps between them that no cell resolves are closed. Every stage runs bounded by
/// options.limits. Deterministic for identical input and options unless the
/// sphere builder hits its time limit (reported). Throws what the stages
/// throw: InputError for unusable input (StageError for a stage beyond its
/// limits), ParameterError for bad options.
PreprocessResult preprocess(const SurfaceMesh& dense, const PreprocessOptions& options = {},
                            const ProgressFn& progress = {}, const std::string& name = "surface");

}  // namespace icd::mesh
