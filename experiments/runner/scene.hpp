#pragma once
/// Scene files: the objects, their materials and poses, the collision budget
/// and mode, the frame count and rate, and what to output. JSON, validated
/// field by field: every error names the file and the field.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <icd/coupling/kinematic_motion.hpp>
#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/world_settings.hpp>

#include <nlohmann/json.hpp>

namespace icd::runner {

/// A parsed JSON document (nlohmann::json: objects keep their keys sorted).
using Json = nlohmann::json;

/// Parses `text` as a scene document: JSON with // and /* */ comments, a
/// leading UTF-8 byte-order mark skipped. Throws icd::InputError
/// "<source>:<line>:<col>: <what>" on malformed input (raw bytes shown as
/// \xNN) and "<source>: <field path>: duplicate key \"k\"" for a key given
/// twice in one object; refuses nesting deeper than 64 and more than 2^20
/// values. A number beyond the double range is kept as +-infinity (+-0 when
/// it underflows), for the reader of the field to refuse with its name.
Json parse_json(std::string_view text, const std::string& source);

/// Reads and parses a file (parse_json); InputError names the file when it
/// is missing, not a regular file (a folder, /dev/zero) or larger than
/// icd::file_limits::kScene (checked before reading). No includes.
Json read_json_file(const std::string& path);

/// Reads a scene file with its includes: a top-level "include" (a path, or
/// an array of paths, relative to the including file) names files whose
/// documents are deep-merged under this one (objects merged key by key,
/// anything else replaced; the including file wins; later includes win over
/// earlier ones). Includes nest up to 8 deep; a cycle is an error naming the
/// chain.
Json read_scene_json(const std::filesystem::path& path);

/// Applies "dotted.path=value" overrides to a scene document (after its
/// includes): the path's parts are object keys or array indices
/// ("objects.1.material.young=2e5"); the value is parsed as JSON, or taken
/// as a string when it is not JSON ("name=probe run"); `key=null` removes
/// the key (as in a JSON merge patch: the field's default applies, e.g.
/// "collision.budget_seconds=null" with "collision.budget_tests=400" for a
/// test budget in a scene that gives seconds). Missing object keys
/// are created (an unknown one is then refused by parse_scene as in a file);
/// an index past the end of an array, a path through a number or a string,
/// or an override without '=' throws InputError naming the override.
void apply_overrides(Json& json, const std::vector<std::string>& overrides);

using coupling::CollisionSpec;
using coupling::BudgetSplit;
using coupling::InterruptedResponse;
using coupling::ObjectKind;
using coupling::PrimitiveSpec;

/// Off-line preprocessing options for a raw mesh (passed to icd-preprocess).
struct PreprocessSpec {
  int coarse_tets = 1500;               ///< target coarse tet count
  int tree_depth = 3;                   ///< sphere-tree levels below the root (paper: 3)
  int tree_branching = 8;               ///< sphere tree branching factor
  std::string tree_builder = "medial";  ///< "medial" (adaptive medial axis) or "octree"
  /// Optimisation of a medial tree: "light", "full" or "shell"
  /// (icd-preprocess --sphere-fit; icd::mesh::SphereFit).
  std::string tree_fit = "light";
};

/// A region of an object's coarse nodes, selected after meshing and
/// placement (in world coordinates, m).
struct RegionSelector {
  enum class Type {
    Box,    ///< min <= x <= max, componentwise
    Plane,  ///< (x - point) . normal <= tolerance (the negative side, normal unit)
    Near,   ///< |x - point| <= distance
  };
  Type type = Type::Box;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  ///< box min; plane or near point
  Eigen::Vector3d b = Eigen::Vector3d::Zero();  ///< box max; plane normal
  double distance = 0;                          ///< near: distance; plane: tolerance
  std::string field;  ///< "<file>: <field path>" for messages

  bool contains(const Eigen::Vector3d& x) const;
};

/// The coarse nodes of `positions` (#V x 3) in any of `regions`, sorted.
/// Throws InputError "<file>: <field>: selects no coarse node ..." for a
/// region that matches none.
std::vector<int> select_nodes(const std::vector<RegionSelector>& regions, const MatX3d& positions);

/// A load on a region of a deformable object's coarse nodes: a force on each
/// selected node, or a total force spread equally over them.
struct LoadSpec {
  std::vector<RegionSelector> region;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< N
  bool total = false;  ///< force is the total over the region (else per node)
};

/// Keyframes of a rigid object's scripted motion; "position" places the
/// object's "position" point (its bounding-box centre), "rotation" turns it
/// about that point from its placed orientation.
struct MotionSpec {
  std::vector<coupling::Keyframe> keys;
};

/// One object of the scene: its role and physics (coupling::ObjectSetup)
/// and where its geometry comes from.
struct ObjectSpec : coupling::ObjectSetup {
  std::filesystem::path mesh;   ///< raw surface mesh (preprocessed and cached on first use)
  std::filesystem::path asset;  ///< or: a preprocessed asset bundle folder
  std::optional<PrimitiveSpec> primitive;  ///< or: a generated mesh
  PreprocessSpec preprocess;
  double size = 0;  ///< scale so the longest bounding-box side is this (m); 0 = keep units
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      ///< of the bounding-box centre, m
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  ///< XYZ Euler angles, degrees
  /// "collider": a static box primitive collides as an analytic box obstacle
  /// ("analytic", default) or through its sphere tree ("spheres").
  bool analytic_collider = true;
  /// "fixed": regions whose coarse nodes are held fixed (with fixed_nodes).
  std::vector<RegionSelector> fixed_regions;
  std::vector<LoadSpec> loads;       ///< "loads"
  std::optional<MotionSpec> motion;  ///< "motion" (rigid objects)
  /// "initial_compression": fraction in [0, 0.95] of the object's x extent
  /// removed at the start: its coarse nodes are squeezed along x about their
  /// centroid (velocities unchanged) and then released (deformable objects;
  /// the stability study's 70 % cases). 0 = none.
  double initial_compression = 0;
};

/// Resolves the object's regions on its placed coarse nodes: appends the
/// fixed regions' nodes to setup.fixed_nodes (no duplicates), sets
/// setup.motion from the keyframes (pivot: spec.position), and returns the
/// loads as forces per coarse node (#V x 3; empty when there are none).
/// Throws InputError naming the field for a region that selects no node.
MatX3d apply_regions(const ObjectSpec& spec, coupling::ObjectSetup& setup, const MatX3d& coarse);

/// What the run writes.
struct OutputSpec {
  bool csv = true;               ///< per-frame metrics, frames.csv
  int vtu_every = 0;             ///< write meshes every N frames as a VTU/PVD series (0 = never)
  bool dense = true;             ///< VTU output includes the dense meshes (needs the rigid links)
  bool spheres = true;           ///< VTU output includes the spheres used for the response
};

/// A whole scene.
struct Scene {
  std::string name = "scene";
  int frames = 120;
  std::vector<ObjectSpec> objects;
  /// Frame rate, gravity, real-time target, collision detection and response
  /// ("output.exact_reference" sets world.exact_reference; world.dense_meshes
  /// follows the output, see world_settings()).
  coupling::WorldSettings world;
  OutputSpec output;
  std::filesystem::path base_dir;  ///< relative paths in the file resolve against this
};

/// Builds a Scene from parsed JSON. Unknown fields are errors (a typo must
/// not silently fall back to a default). Throws InputError
/// "<source>: <field path>: <what>", e.g. "s.json: objects[1].material.poisson:
/// must be in (-1, 0.5), got 0.5".
Scene parse_scene(const Json& json, const std::string& source,
                  const std::filesystem::path& base_dir);

/// The settings a World runs the scene with: scene.world, with the dense
/// meshes kept up to date when the output writes them.
coupling::WorldSettings world_settings(const Scene& scene);

/// Reads and parses a scene file (read_scene_json: regular files of at most
/// 64 MiB, with their includes), after the `overrides` (apply_overrides);
/// relative paths resolve against its folder, then against the repository
/// root (so shipped scenes find data/). The paths are only resolved here:
/// check_scene_inputs (run.hpp) checks that they exist.
Scene load_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});

}  // namespace icd::runner
