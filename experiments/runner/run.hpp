#pragma once
/// Running a scene end to end: progress, per-range summaries, per-frame CSV,
/// optional VTU/PVD time series. Shared by icd-run, icd-main and the tests.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <string>

#include <icd/coupling/world.hpp>
#include <icd/mesh/io/vtk_types.hpp>

#include "experiments/runner/child_process.hpp"
#include "experiments/runner/scene.hpp"

namespace icd::runner {

using coupling::FrameMetrics;
using coupling::RuntimeObject;
using coupling::World;

/// The objects' setups of a scene, in scene order.
std::vector<coupling::ObjectSetup> object_setups(const Scene& scene);

/// The stages the scene needs (coupling::make_plan of its objects and settings).
coupling::StagePlan scene_plan(const Scene& scene);

/// The scene's stages and what it outputs, one line each (icd-run --dry-run).
std::vector<std::string> describe_plan(const Scene& scene);

/// Checks every input path of the scene without loading anything
/// (check_object_inputs of each object): what icd-run --dry-run checks.
/// Throws InputError naming the object and the file.
void check_scene_inputs(const Scene& scene);

/// Loads every object of the scene (load_object_asset: primitive, bundle, or
/// raw mesh preprocessed into `cache_dir` by the icd-preprocess tool in
/// `tool_dir`, run under `limits`), places it, prints scale_warnings() to
/// stderr, and builds the World with world_settings(scene). Checks every
/// input path first (check_scene_inputs), so that a missing file is reported
/// before any preprocessing.
World make_world(const Scene& scene, const std::filesystem::path& cache_dir,
                 const std::filesystem::path& tool_dir, const ChildLimits& limits = {});

/// One line per deformable object of `world` with mass scaling on: what
/// fem::MassScalingReport::to_string says, prefixed with the object's name.
std::vector<std::string> describe_mass_scaling(const World& world);

/// Warnings, one sentence each naming the object, when the placed objects'
/// sizes suggest a unit mismatch (an asset left in millimetres beside objects
/// in metres): an object more than 100 times larger or smaller than another
/// (sizes: bounding-box diagonals of the dense meshes), or more than 100
/// times larger than the distance spanned by the objects' positions.
std::vector<std::string> scale_warnings(const std::vector<coupling::WorldObject>& objects);

/// `name` made safe as one file-name component: every byte but [A-Za-z0-9._-]
/// becomes '_', a leading '.' becomes '_' (no "..", no hidden file), at most
/// 100 bytes, never empty. A scene or object name is a label, not a path.
std::string file_name_from(const std::string& name);

/// Options of run_scene().
struct RunOptions {
  std::filesystem::path out_dir;    ///< results folder (created); required
  std::filesystem::path cache_dir;  ///< preprocessed assets cache
  std::filesystem::path tool_dir;   ///< where icd-preprocess lives
  ChildLimits preprocess_limits;    ///< CPU, wall-clock and memory limits of icd-preprocess
  int frames = -1;                  ///< override the scene's frame count (-1 = keep; else >= 1)
  double target_fps = -1;           ///< override the scene's real-time target (-1 = keep, 0 = off)
  bool progress = true;             ///< progress bar on stderr
  int summary_ranges = 4;           ///< summary lines (frame ranges) printed at the end
  std::FILE* log = stdout;          ///< where summaries go (nullptr = silent)
  /// The scene file run, copied as <out_dir>/scene.json beside version.txt
  /// (empty: no copy), so a results folder records what made it.
  std::filesystem::path scene_file;
};

/// Runs the scene and writes `<out_dir>/frames.csv`, `version.txt` (the
/// program version) and a copy of options.scene_file as `scene.json`, and if
/// asked the VTU series in `<out_dir>/vtu/`: per written frame, the coarse
/// meshes (binary VTU; point data displacement, velocity, contact_force,
/// external_force; cell data volume_ratio), the dense meshes (displacement)
/// and each pair side's contact spheres (radius, level, colliding_leaf), all
/// listed as parts of one collection, run.pvd; and each object's whole sphere
/// tree at the start, <name>_tree.vtu (radius, level, leaf). File names are
/// file_name_from(object name), made unique.
/// Files are written under temporary names and renamed at the end, so an
/// interrupted run leaves no complete-looking output. Returns the metrics of
/// every frame. Throws ParameterError for a frame count below 1 (as the scene
/// file refuses), and on any error (after removing partial files).
std::vector<FrameMetrics> run_scene(const Scene& scene, const RunOptions& options);

/// Writes, as a VTU sphere set at `path`, the spheres of one side of
/// collision pair `pair` (side 0: the pair's first object, 1: its second)
/// that the last query used for the contact response: the colliding leaf
/// pairs' spheres and the untested pairs' spheres (paper 4.3, Fig. 9), with
/// point arrays "level" (tree level) and "colliding_leaf" (1: from a
/// colliding leaf pair, 0: from an untested pair).
/// `options` picks the encoding (ASCII by default, which read_vtu reads).
void write_contact_spheres(World& world, size_t pair, int side, const std::filesystem::path& path,
                           const VtuOptions& options = {});

/// Real-time mode over a run: frames with a deadline, how many met it, the
/// worst lateness (s), frames where FEM alone exceeded it, and what was cut.
struct RealTimeSummary {
  int frames = 0, met = 0, fem_over = 0;
  double worst_lateness = 0;
  int min_budget_queries = 0, interrupted = 0;
  int64_t untested = 0;  ///< untested sphere pairs left at the frames' ends (PAIRLIST)
};
RealTimeSummary summarize_real_time(const std::vector<FrameMetrics>& frames);

/// The per-frame CSV (header + one row per frame).
std::string metrics_csv(const std::vector<FrameMetrics>& frames);

}  // namespace icd::runner
