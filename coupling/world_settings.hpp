#pragma once
/// What a simulation is made of, before it runs: each object's role and
/// physics (WorldObject), and the scene-wide settings of the frame loop and
/// of the collision detection and response (WorldSettings, CollisionSpec).
/// Plain data with one default per value; validate() checks them once.
#include <string>
#include <vector>

#include <Eigen/Core>

#include <icd/collision/sphere_update.hpp>
#include <icd/collision/traversal.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/coupling/contact_response.hpp>
#include <icd/coupling/kinematic_motion.hpp>
#include <icd/coupling/obstacle.hpp>
#include <icd/fem/integrators.hpp>
#include <icd/fem/material.hpp>
#include <icd/fem/model.hpp>

namespace icd::coupling {

/// How an object moves.
enum class ObjectKind {
  Deformable,  ///< explicit FEM on the coarse mesh (paper section 3)
  Rigid,       ///< kinematic: follows its motion (or its initial velocity), no FEM
  Static,      ///< never moves: no FEM, no sphere update
};

/// One object's role and physics (no geometry).
struct ObjectSetup {
  std::string name;
  ObjectKind kind = ObjectKind::Deformable;
  fem::Material material;
  fem::RayleighDamping damping;
  fem::Integrator integrator = fem::Integrator::RK4;
  /// Selective mass scaling of a deformable object (fem::MassScaling::
  /// target_ratio, 0: off; scene field "fem": {"mass_scaling_target"}): its
  /// light nodes get just enough mass for a stable step of this fraction of
  /// near-regular tets' (why 0.5 and what it costs in accuracy: fem/README.md).
  double mass_scaling_target = fem::kSceneMassScalingTarget;
  std::vector<int> fixed_nodes;  ///< coarse node indices held fixed
  /// Initial velocity of a deformable object, constant velocity of a rigid one, m/s.
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  /// A rigid object with a motion is placed at motion(t) * rest at the end
  /// of every cycle (t: simulated time, s) instead of moving with
  /// `velocity` (e.g. KeyframeMotion::function(); World::set_kinematic_motion).
  MotionFunction motion;
  /// false: the object takes no part in sphere-tree collisions (e.g. a static
  /// box that collides as an analytic obstacle, WorldSettings::obstacles).
  bool sphere_collisions = true;
  /// User weight of the object's pairs when one query budget is shared by
  /// priority (CollisionSpec::budget_split = Priority), > 0: e.g. larger for
  /// objects near the camera. A pair's weight is the product of its objects'.
  double collision_weight = 1;
};

/// One object ready to simulate: its setup and its geometry (dense surface,
/// coarse tets, rigid links, sphere tree with its node association), placed
/// in world units (m).
struct WorldObject {
  ObjectSetup setup;
  AssetBundle asset;
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

/// How the query budget of a cycle is shared among the pairs that need a
/// query (their swept trees touch and their roots overlap).
enum class BudgetSplit {
  /// Every pair gets the request's budget (in real-time mode: an equal share
  /// of what is left of the frame).
  Even,
  /// Level of detail for many pairs (the paper's closing idea): the same
  /// total, n pairs x the even budget, shared by each pair's priority
  /// w = w_a w_b (1 + depth / leaf + closing speed x frame / leaf): the user
  /// weights of its objects (ObjectSetup::collision_weight), its deepest
  /// penetration in the last response and the speed at which its objects'
  /// centres approach, both in leaf radii of the pair's smaller tree. The
  /// pairs are queried lowest priority first, each with its weight's
  /// fraction of what is left of the total (tests, or seconds measured), so
  /// what resting pairs do not use goes to deep or fast-closing ones; each
  /// gets at least one test (min_query_budget in seconds).
  Priority,
  /// Level of detail by cost: the same total, n pairs x the even budget,
  /// handed whole to the cheapest pairs first. Each pair's complete cost is
  /// estimated from its last complete query (tests, or seconds measured;
  /// after an interrupted query: at least what it used; never queried:
  /// last); in that order each pair whose estimate fits in what is
  /// left (one test, or min_query_budget, set aside for each later pair)
  /// gets what is left, up to twice its estimate, so it is answered
  /// completely; once one does not fit, it and the later pairs share what
  /// is left evenly. The total of a cycle's queries never exceeds the pool
  /// (in tests). A weight split moves a part of the tests and so moves the
  /// cut within a level (three_pairs: no better than even); this completes
  /// as many pairs as the pool can pay for.
  Cheapest,
};

/// The collision request of every pair query of a simulation: 1 ms per
/// query in the fast breadth-first mode.
inline collision::CollisionRequest default_query() {
  collision::CollisionRequest r;
  r.budget_seconds = 1e-3;
  return r;
}

/// Collision detection and response settings.
struct CollisionSpec {
  /// The request of every pair query: budget (budget_seconds, or
  /// budget_tests for deterministic runs), traversal mode, clock interval,
  /// depth cap, list cap, parent filter. start_front and record_front are
  /// set per query by the World (temporal_coherence).
  collision::CollisionRequest query = default_query();
  /// How one cycle's query budget is shared among its pairs.
  BudgetSplit budget_split = BudgetSplit::Even;
  /// Seed each query with the previous query's front of the same pair.
  bool temporal_coherence = false;
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
  /// With single_cycle_when_apart and swept: skip the trial when the spheres
  /// moved on with their node velocities touch within the frame (the trial
  /// would be rolled back): such a frame runs in cycles at once
  /// (World::contact_ahead, FrameMetrics::predicted). false: always the trial.
  bool predict_contact = true;
  /// Continuous detection (not in the paper): each cycle first queries the
  /// swept trees (every sphere grown to enclose its positions at the cycle's
  /// start and end, collision/swept_spheres.hpp), so two objects that cross
  /// each other between two queries are still found. A pair whose swept trees
  /// are apart skips its end-of-cycle query. A cycle that starts contact-free
  /// and ends in a contact deeper than the penetrating leaf's radius, or whose
  /// sweep touched while its end did not after a motion larger than a leaf, is
  /// rolled back and re-run in shorter cycles (FrameMetrics::subdivided).
  bool swept = true;
  /// Largest motion of a pair relative to each other per cycle, as a fraction
  /// of the smaller of their median leaf radii, when frames are cut into
  /// cycles by motion (in contact, or after a frame tried as one cycle found
  /// a contact). Bounds the depth at which a contact is first seen.
  double cycle_motion = 0.5;
  /// Detect at the coarse positions predicted for the middle of the next
  /// cycle (x + h v / 2), during which the resulting forces act, instead of
  /// at its start: the staggered penalty then engages and releases half a
  /// cycle earlier, centred on the contact, which cancels most of the energy
  /// it would otherwise gain per contact.
  bool midpoint = true;
  /// Keep the response passive: over a contact episode (from first contact
  /// until every pair is apart again) the contact forces may give the
  /// objects back the work they absorbed, plus World::kPassiveTolerance of
  /// the kinetic energy at the episode's start, not more. A cycle whose
  /// forces would do more is scaled down. A switching contact set (an
  /// interrupted query answering with coarser or partial pairs, a pair
  /// appearing already overlapping) is not a conservative force and
  /// otherwise gains energy; false: the paper's response as computed.
  bool passive = true;
  /// Cap each coarse node's penalty rate (sum of k share / m_n over its
  /// pairs) at 0.45 (World::kContactOmegaLimit / h)^2 per object, h the cycle
  /// length, by weighting the pairs of overloaded nodes
  /// (ContactOptions::node_rate_limit): hundreds of leaf pairs on one node
  /// no longer make the whole response softened (the main job: 151 softened
  /// cycles and a pair 2.90 leaf radii deep without the cap; with it none
  /// and 1.42 with deep_step_ratio). false: the summed stiffness as is.
  bool node_rate_cap = true;
  /// With node_rate_cap: the penalty asks for no cycles shorter than the
  /// FEM sub-step of the objects that run them (the shortest of theirs):
  /// the cap keeps every node's penalty rate under the explicit limit at any
  /// cycle length, so each cycle may cost each object one sub-step
  /// (World::contact_cycles). The count is the fewer of that and the rule
  /// below, for slow contacts only (each pair closing by at most a third of
  /// collision.cycle_motion per cycle at that count: with the cap, longer
  /// cycles mean a softer penalty, and balls thrown head-on at 5 m/s sank
  /// 2.6 leaf radii deep). On by default since the deep-contact velocity
  /// step is order-free (deep_contact_velocity_step): the 0.6 m/s head-on
  /// bounce of HeadOn.SoftSpheresBounceApartSymmetrically leaves with 1.52 %
  /// sideways drift with it, 1.18 % with the rule below (bound 2 %; with
  /// the earlier pair-by-pair step 2.07 % and 1.95 %; without deep steps
  /// 1.16 %: the rest is the penalty between two trees that are not mirror
  /// images). Main job: contact frames 128 -> 74-76 sub-steps, every frame
  /// within a 60 Hz deadline.
  /// false, or without the cap: as many cycles as the full stiffness
  /// (at least contact.stiffness) on the lightest node needs for omega h <=
  /// 0.25 (on the main job's light nodes its maximum, 64: two cycles per
  /// sub-step, 128 sub-steps per contact frame instead of ~70).
  bool cycles_at_fem_step = true;
  /// A colliding leaf pair deeper than this fraction of its smaller radius
  /// that still approaches gets an inelastic velocity step on its coarse
  /// nodes (deep_contact_velocity_step: momentum kept, kinetic energy only
  /// removed, no order among the pairs), so it stops sinking deeper. 0: off
  /// (the penalty alone).
  double deep_step_ratio = 0.5;
  collision::SphereUpdateOptions update;
  ContactOptions contact;
  InterruptedResponse on_interrupt = InterruptedResponse::Previous;
  /// Oldest complete answer on_interrupt = Previous reuses as is, simulated
  /// s. Reusing an old answer misses contacts that began since (a pair that
  /// was apart stays apart), so by default one 60 Hz frame.
  double previous_max_age = 1.0 / 60;
};

/// Scene-wide settings of a simulation.
struct WorldSettings {
  double frame_rate = 60;  ///< simulated frames per simulated second
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< m/s^2
  /// Real-time mode: hold this wall-clock frame rate, collision detection
  /// getting what is left of each frame (0 = off). Each frame's deadline is
  /// 1 / target_fps of wall time; FEM is never skipped (see FrameMetrics::
  /// deadline_met, lateness, fem_over_deadline).
  double target_fps = 0;
  /// Real-time mode: the smallest time budget a pair query gets, s (> 0),
  /// even when the frame is already late: collision is never cut to nothing.
  double min_query_budget = 1e-4;
  /// Threads that advance the objects (each object's FEM sub-steps, rigid
  /// links and sphere update on one worker; contact between them at the
  /// cycle boundary). With fewer deformable objects than threads, the FEM
  /// force loop of each splits across the rest. Results are bitwise
  /// identical for any count. 0: the hardware concurrency.
  int threads = 0;
  /// How long an idle worker spins before it blocks, s (>= 0; 0: blocks at
  /// once, the default: see WorkerPool for the measurements).
  double worker_spin = 0;
  CollisionSpec collision;
  /// Static analytic obstacles (planes, boxes) that deformable objects are
  /// kept out of by projection (coupling/obstacle.hpp).
  std::vector<Obstacle> obstacles;
  /// Test against the obstacles only the dense vertices that may be near
  /// one (a bound from the coarse nodes and the link lengths, see
  /// World::obstacle_layer; bitwise the same results). false: every vertex
  /// of an object within reach against every obstacle, each time (the
  /// reference the cull is tested against).
  bool obstacle_cull = true;
  /// Keep the dense meshes of moving objects up to date every frame (the
  /// rigid links; for output). Without it they are evaluated only where the
  /// exact reference needs them.
  bool dense_meshes = false;
  /// Per frame, count the exactly intersecting dense triangle pairs
  /// (FrameMetrics::exact_contacts; needs the dense meshes).
  bool exact_reference = false;
};

/// Checks the settings (rates, budgets, the query request) and throws
/// ParameterError naming the field, e.g. "collision.query.budget_seconds:
/// must be > 0 (infinity for none), got 0".
void validate(const WorldSettings& settings);

}  // namespace icd::coupling
