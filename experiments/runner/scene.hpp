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

#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/world_settings.hpp>

#include "experiments/runner/json.hpp"

namespace icd::runner {

using coupling::CollisionSpec;
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
};

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

/// Reads and parses a scene file (read_json_file: a regular file of at most
/// 64 MiB); relative paths resolve against its folder, then against the
/// repository root (so shipped scenes find data/). The paths are only
/// resolved here: check_scene_inputs (run.hpp) checks that they exist.
Scene load_scene(const std::filesystem::path& path);

}  // namespace icd::runner
