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

#include "collision/sphere_update.hpp"
#include "collision/traversal.hpp"
#include "coupling/contact_response.hpp"
#include "experiments/runner/json.hpp"
#include "fem/integrators.hpp"
#include "fem/material.hpp"
#include "fem/model.hpp"

namespace icd::runner {

/// How an object moves.
enum class ObjectKind {
  Deformable,  ///< explicit FEM on the coarse mesh (paper section 3)
  Rigid,       ///< kinematic: moves with its initial velocity, no FEM
  Static,      ///< never moves: no FEM, no sphere update
};

/// A mesh generated in code (no preprocessing needed): dense icosphere or box
/// surface on a structured coarse tet mesh.
struct PrimitiveSpec {
  std::string type = "sphere";            ///< "sphere" or "box"
  double radius = 0.1;                    ///< sphere radius, m
  Eigen::Vector3d extent{0.2, 0.2, 0.2};  ///< box sides, m
  int subdivisions = 3;                   ///< icosphere subdivisions of the dense surface
  int cells = 4;                          ///< coarse cells along the longest side
};

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

/// One object of the scene.
struct ObjectSpec {
  std::string name;
  std::filesystem::path mesh;   ///< raw surface mesh (preprocessed and cached on first use)
  std::filesystem::path asset;  ///< or: a preprocessed asset bundle folder
  std::optional<PrimitiveSpec> primitive;  ///< or: a generated mesh
  PreprocessSpec preprocess;
  double size = 0;  ///< scale so the longest bounding-box side is this (m); 0 = keep units
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      ///< of the bounding-box centre, m
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  ///< XYZ Euler angles, degrees
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      ///< initial, m/s
  ObjectKind kind = ObjectKind::Deformable;
  fem::Material material;
  fem::RayleighDamping damping;
  fem::Integrator integrator = fem::Integrator::RK4;
  std::vector<int> fixed_nodes;  ///< coarse node indices held fixed
};

/// What the response uses when a query is interrupted by its budget.
enum class InterruptedResponse {
  /// The paper (4.2): the untested pairs (PAIRLIST) count as colliding, with
  /// their own, coarser spheres. An interruption at a coarse level (e.g. the
  /// process lost the processor for longer than the budget) then pushes with
  /// the penetration of large inner spheres: an energy kick.
  Untested,
  /// The last complete answer of the pair, if it is at most
  /// CollisionSpec::previous_max_age old, re-evaluated at the current sphere
  /// positions. If it is older, the untested pairs respond (as Untested) but
  /// none deeper than that answer's deepest pair (when it had a contact).
  /// With no complete answer yet: as Untested.
  Previous,
};

/// Collision detection and response settings.
struct CollisionSpec {
  double budget_seconds = 1e-3;  ///< critical time per pair query (s); inf = none
  int64_t budget_tests = -1;     ///< or a budget in sphere tests (deterministic); -1 = none
  collision::TraversalMode mode = collision::TraversalMode::BreadthFirstFifo;
  bool literal = false;  ///< the paper's Fig. 7 literally (test on pop, clock every test)
  int clock_check_interval = 16;
  std::size_t max_list_size = 1 << 14;  ///< priority mode cap
  int depth_cap = -1;                   ///< -1 = none
  bool temporal_coherence = false;
  /// collision::CollisionRequest::parent_filter (not with fifo_literal). Pays
  /// only on wrapped trees (layered false): on layered trees it prunes nothing
  /// and its own tests are extra.
  bool parent_filter = false;
  /// After each update, grow parents to enclose their children (a layered
  /// tree): the penalty force then grows continuously from first contact.
  /// false keeps the paper's wrapped tree, where a leaf pair can appear
  /// already deeply overlapping once its parents start to overlap (an energy
  /// kick: a ball bouncing between static walls gained ~30x its energy).
  bool layered = true;
  /// A frame that starts with every pair apart runs as one detection/response
  /// cycle, rolled back and re-run in full cycles if its closing query finds
  /// a contact (see World::step). false: every frame runs all its cycles.
  bool single_cycle_when_apart = true;
  /// Detect at the coarse positions predicted for the middle of the next
  /// cycle (x + h v / 2), during which the resulting forces act, instead of
  /// at its start: the staggered penalty then engages and releases half a
  /// cycle earlier, centred on the contact, which cancels most of the energy
  /// it would otherwise gain per contact.
  bool midpoint = true;
  /// Keep the response passive: over a contact episode (from first contact
  /// until every pair is apart again) the contact forces may give the
  /// objects back the work they absorbed, plus kPassiveTolerance of the
  /// kinetic energy at the episode's start, not more. A cycle whose forces
  /// would do more is scaled down (World::limit_contact_work). A switching
  /// contact set (an interrupted query answering with coarser or partial
  /// pairs, a pair appearing already overlapping) is not a conservative
  /// force and otherwise gains energy; false: the paper's response as computed.
  bool passive = true;
  collision::SphereUpdateOptions update;
  coupling::ContactOptions contact;
  InterruptedResponse on_interrupt = InterruptedResponse::Previous;
  /// Oldest complete answer on_interrupt = "previous" reuses as is,
  /// simulated s. Reusing an old answer misses contacts that began since
  /// (a pair that was apart stays apart), so by default one 60 Hz frame.
  double previous_max_age = 1.0 / 60;
};

/// What the run writes.
struct OutputSpec {
  bool csv = true;               ///< per-frame metrics, frames.csv
  int vtu_every = 0;             ///< write meshes every N frames as a VTU/PVD series (0 = never)
  bool dense = true;             ///< VTU output includes the dense meshes (needs the rigid links)
  bool spheres = true;           ///< VTU output includes the spheres used for the response
  bool exact_reference = false;  ///< per frame, exact dense triangle contacts (needs dense meshes)
};

/// A whole scene.
struct Scene {
  std::string name = "scene";
  int frames = 120;
  double frame_rate = 60;  ///< simulated frames per simulated second
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  double target_fps = 0;  ///< real-time mode: hold this wall-clock rate (0 = off)
  std::vector<ObjectSpec> objects;
  CollisionSpec collision;
  OutputSpec output;
  std::filesystem::path base_dir;  ///< relative paths in the file resolve against this
};

/// Builds a Scene from parsed JSON. Unknown fields are errors (a typo must
/// not silently fall back to a default). Throws InputError
/// "<source>: <field path>: <what>", e.g. "s.json: objects[1].material.poisson:
/// must be in (-1, 0.5), got 0.5".
Scene parse_scene(const Json& json, const std::string& source,
                  const std::filesystem::path& base_dir);

/// Reads and parses a scene file; relative paths resolve against its folder,
/// then against the repository root (so shipped scenes find data/).
Scene load_scene(const std::filesystem::path& path);

}  // namespace icd::runner
