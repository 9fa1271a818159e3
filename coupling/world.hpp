#pragma once
/// The simulation loop (paper sections 3.2, 4 and 5): FEM on the coarse
/// meshes, sphere-tree update, interruptible collision detection, penalty
/// response, rigid links, each stage only where the plan needs it. A library
/// type: it takes loaded objects and does no file I/O.
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <icd/collision/swept_spheres.hpp>
#include <icd/collision/traversal.hpp>
#include <icd/coupling/link_evaluator.hpp>
#include <icd/coupling/stage_plan.hpp>
#include <icd/coupling/world_settings.hpp>
#include <icd/coupling/worker_pool.hpp>
#include <icd/fem/simulator.hpp>

namespace icd::coupling {

/// Wall time of each stage in one frame, seconds.
struct StageTimes {
  double fem = 0, links = 0, sphere_update = 0, collision = 0, response = 0, output = 0;
  double total() const { return fem + links + sphere_update + collision + response + output; }
};

/// Metrics of one frame (summed over object pairs where that makes sense).
struct FrameMetrics {
  int frame = 0;
  double time = 0;  ///< simulated time at the end of the frame, s
  StageTimes times;
  double wall = 0;             ///< wall time of the whole frame, s
  double budget = 0;           ///< time budget given to each query, s (inf = none)
  int64_t pair_list = 0;       ///< PAIRLIST size at the end of the queries (untested pairs)
  int64_t collision_list = 0;  ///< COLLISIONLIST size (colliding leaf pairs)
  int64_t tests = 0;           ///< sphere tests done
  int interrupted = 0;         ///< queries interrupted by their budget
  int completed_level = 0;     ///< smallest completed level over the queries
  int active_pairs = 0;        ///< sphere pairs that produced a force
  double max_penetration = 0;  ///< deepest sphere penetration, m
  double contact_force = 0;    ///< |total contact force| on the first object of each pair, N (sum)
  int cycles = 1;              ///< detection/response cycles in the frame (stable penalty)
  /// 1 when the frame was first tried as one contact-free cycle, found a
  /// contact at its end, and was rolled back and re-run in `cycles` cycles.
  int rollback = 0;
  /// 1 when the frame started contact-free but was run in cycles at once,
  /// without the single-cycle trial, because the objects' spheres moved on
  /// with their node velocities touched within it (World::contact_ahead).
  int predicted = 0;
  /// Interrupted queries whose response used the pair's previous complete
  /// answer (collision.on_interrupt = "previous").
  int reused = 0;
  /// Cycles whose penalty forces were scaled down because a node's penalty
  /// stiffness over its mass exceeded what the cycle length allows (see
  /// World::kContactOmegaLimit).
  int softened = 0;
  /// Cycles whose penalty forces were scaled down to keep the contact
  /// passive (collision.passive).
  int limited = 0;
  int substeps = 0;     ///< FEM sub-steps summed over objects
  /// The two lower bounds the frame's cycle count came from (before it was
  /// fitted to the sub-steps, World::fit_cycles), 0 for a frame run as one
  /// contact-free cycle: the penalty's (World::contact_cycles) and the
  /// motion's (collision.cycle_motion, obstacles; World::motion_cycles).
  int cycles_penalty = 0;
  int cycles_motion = 0;
  /// Lanczos products the objects' stable-step estimates took in the frame
  /// (fem::AdvanceReport::frequency_products summed; 0: every estimate reused).
  int frequency_products = 0;
  double min_step = 0;  ///< smallest FEM step used, s
  /// Mechanical energy of the deformable objects, J: kinetic + elastic +
  /// gravity potential, plus the energy in the penalty springs of the last
  /// response (contact forces are not counted as loads with a potential).
  double energy = 0;
  /// The part of `energy` held by the penalty springs of the last response, J
  /// (for an interrupted query, springs between coarse spheres assumed colliding).
  double penalty_energy = 0;
  int exact_contacts = -1;  ///< exact intersecting dense triangle pairs (-1: not computed)
  /// Cycles rolled back and re-run in shorter cycles (collision.swept): a
  /// contact first seen deeper than a leaf radius, or a sweep that touched
  /// while the cycle's end was apart after a motion larger than a leaf.
  int subdivided = 0;
  /// Dense vertices found inside a static obstacle (and projected out) in
  /// the frame's last cycle.
  int obstacle_vertices = 0;
  /// Deepest a dense vertex was found inside an obstacle before its
  /// projection, over the frame's cycles, m.
  double obstacle_depth = 0;
  /// Largest number of colliding leaf pairs deeper than the smaller of their
  /// radii in one cycle of the frame (ContactStats::deep_pairs): the surfaces
  /// have passed through each other by more than the spheres resolve.
  int deep_pairs = 0;
  /// Largest penetration / smaller leaf radius of a colliding leaf pair in
  /// the frame (> 1 with deep_pairs).
  double depth_ratio = 0;
  /// Pair forces weighted down by the per-node rate cap
  /// (collision.node_rate_cap), summed over the frame's cycles.
  int64_t capped_pairs = 0;
  /// Deep approaching leaf pairs given an inelastic velocity step
  /// (collision.deep_step_ratio), summed over the frame's cycles.
  int deep_steps = 0;
  /// Kinetic energy those steps removed in the frame, J.
  double deep_step_energy = 0;
  /// Real-time mode (WorldSettings::target_fps > 0): the frame's deadline,
  /// 1 / target_fps of wall time, s (0: not in real-time mode).
  double deadline = 0;
  /// 1 when the frame's wall time stayed within its deadline, 0 when it did
  /// not, -1 outside real-time mode.
  int deadline_met = -1;
  /// wall - deadline when the deadline was missed, else 0, s.
  double lateness = 0;
  /// Queries of the frame that ran at WorldSettings::min_query_budget because
  /// less than that was left of the frame (collision cut to its minimum).
  int min_budget_queries = 0;
  /// 1 when FEM, rigid links and the sphere update alone took longer than
  /// the deadline: no collision budget could have kept it.
  int fem_over_deadline = 0;
  /// Set in the first frame whose FEM alone exceeds the deadline (once per
  /// World): what it costs and what the deadline is, for the user.
  std::string deadline_warning;
};

/// One object at run time.
struct RuntimeObject {
  ObjectSetup setup;
  ObjectPlan plan;
  AssetBundle asset;  ///< the sphere tree's current spheres follow the coarse nodes
  std::unique_ptr<fem::Simulator> sim;  ///< deformable objects only (not movable: held by pointer)
  MatX3d positions;                     ///< current coarse positions (#V x 3)
  MatX3d rest;                          ///< rest coarse positions, placed in the world
  MatX3d contact_forces;                ///< forces from the last collision response (#V x 3)
  /// Loads set by the user on the coarse nodes (N, #V x 3; empty = none),
  /// held until changed: a scripted or haptic probe, a pull. They act on
  /// deformable objects beside the contact forces (and gravity).
  MatX3d external_forces;
  MatX3d dense;                         ///< current dense positions (when the plan updates them)
  LinkEvaluator links;            ///< the rigid links, grouped by node triple (when dense_update)
  MatX3d predicted;               ///< coarse positions half a cycle ahead (collision.midpoint)
  MatX3d corotated;               ///< scratch: coarse positions in the co-rotated frame
  Eigen::VectorXd node_mass;      ///< lumped coarse node masses (kg); huge for objects without FEM
  /// collision.swept: the spheres at the start of the cycle (actual
  /// positions, not the midpoint prediction), at its end, and swept from the
  /// start to the end (or to the midpoint prediction, via the end).
  std::vector<collision::Sphere> start_spheres, end_spheres;
  std::vector<collision::SweptSphere> swept;
  double motion = 0;       ///< largest sphere motion in the last cycle, m
  double speed = 0;        ///< motion / cycle length of the last cycle, m/s
  double leaf_radius = 0;  ///< median rest leaf radius, m (scale of the motion per cycle)
  /// Obstacles: the longest rigid link (m), the object's motion scale (its
  /// median leaf radius, m), and scratch dense positions.
  double max_link = 0;
  double obstacle_scale = 0;
  /// Deepest a dense vertex was found inside an obstacle by the last
  /// cycle's projection over that cycle's length, m/s (a measured
  /// approach speed, World::obstacle_approach).
  double obstacle_rate = 0;
  MatX3d obstacle_dense;
  /// Per link triple (LinkEvaluator): the longest link vector |c| of its
  /// links, m (-1: some link has a negative origin weight, no bound: always
  /// evaluated). A link's vertex lies within it of its origin, a convex
  /// combination of the triple's nodes (World::obstacle_layer).
  std::vector<double> triple_reach;
  /// Per link, in the order of LinkEvaluator::triple_links(): its origin
  /// weights alpha_0..2 and the length of its link vector |c| (m; its vertex
  /// lies within it of its origin), 4 doubles (World::obstacle_layer).
  std::vector<double> link_bound;
  /// Scratch of the obstacle handling: the obstacles within reach, the node
  /// coordinates in each one's frame, the triples and the dense vertices
  /// (in triple order) that may be near one.
  std::vector<int> obstacle_near;
  std::vector<MatX3d> obstacle_local;
  std::vector<int32_t> obstacle_triples, obstacle_layer;
  std::vector<double> obstacle_scratch;
  /// The triples that may come within obstacle_list_threshold +
  /// World::kObstacleListMargin of the obstacles obstacle_list_near, found
  /// at the node positions obstacle_list_from (World::obstacle_layer).
  std::vector<int32_t> obstacle_list;
  std::vector<int> obstacle_list_near;
  double obstacle_list_threshold = 0;
  MatX3d obstacle_list_from;
  bool near_obstacle = false;  ///< came within reach of an obstacle in the last cycle
  /// Support of the obstacles for the coming cycle (#coarse nodes x 3, N;
  /// empty when none): see World::obstacle_support.
  MatX3d obstacle_support;
  /// Energy the obstacles added (support work, projection) that the
  /// kinetic energy could not pay for yet (J): paid by the next cycles.
  double obstacle_debt = 0;
  int substeps = 0;            ///< FEM sub-steps of this object in the last frame
  double step = 0;             ///< its last FEM sub-step, s (its own stable step)
  /// The sub-step its FEM takes over an interval longer than it, at the last
  /// stable-step estimate: min(max_step, safety_factor x stable limit), s
  /// (0: not advanced yet). World::aligned_cycles sizes cycles by it.
  double step_cap = 0;
  /// Scratch of one cycle's parallel stage, reduced in object order after
  /// it: contact work terms f . x0 and f . x1 (J), sub-steps, smallest
  /// step, dense vertices found inside obstacles and the deepest.
  double work_before = 0, work_after = 0;
  int cycle_substeps = 0;
  int cycle_products = 0;
  double stage_seconds[3] = {0, 0, 0};  ///< wall time of its FEM, links, sphere update in the cycle
  double cycle_min_step = 0;
  int cycle_obstacle_vertices = 0;
  double cycle_obstacle_depth = 0;
  /// Kinematic objects: the current pose (positions = pose * rest).
  RigidPose pose;
  /// Deformable object in no close pair and not near an obstacle this frame
  /// (World::plan_islands): it skips the frame's cycles but the last and then
  /// advances over the whole frame at once (its FEM, sphere update and
  /// queries), so it does not pay for the cycles others' contacts need.
  bool deferred = false;
  /// Simulated time this object is behind the World's cycle clock, s (> 0
  /// only for a deferred object inside a frame).
  double lag = 0;
  /// Simulated time its last advance covered, s (its cycle length, or the
  /// whole frame for a deferred object).
  double advanced = 0;
};

/// A simulation: objects, the plan of the stages they need, and the frame loop.
class World {
 public:
  /// Sets up the plan and the FEM models of `objects` (placed in world
  /// units). Trees are cut below the plan's deepest usable level and, with
  /// collision.layered, their parents grown to enclose their children.
  /// Throws ParameterError for invalid settings and InputError naming the
  /// object for an invalid object (e.g. a fixed node out of range).
  World(std::vector<WorldObject> objects, WorldSettings settings);

  const WorldSettings& settings() const { return m_settings; }
  const StagePlan& plan() const { return m_plan; }
  /// Threads advancing the objects (WorldSettings::threads resolved).
  int threads() const { return m_threads; }
  std::vector<RuntimeObject>& objects() { return m_objects; }
  const std::vector<RuntimeObject>& objects() const { return m_objects; }
  /// Sets the user loads of object `i` (N per coarse node, #V x 3; an empty
  /// matrix removes them). Throws ParameterError for a wrong shape or a
  /// non-finite entry, naming the object.
  void set_external_forces(int i, const MatX3d& forces);
  /// Scripts kinematic (rigid) object `i`: from the next cycle on it is
  /// placed at motion(t) * rest (t: simulated time at the end of each cycle);
  /// an empty function returns it to its constant velocity from its current
  /// pose. Throws ParameterError when the object is not rigid.
  void set_kinematic_motion(int i, MotionFunction motion);
  /// Moves kinematic object `i` to `pose` (of its rest nodes) over the next
  /// frame (translation linear, rotation slerp, from its current pose), then
  /// holds it there: a probe driven frame by frame (haptics, Python).
  void set_kinematic_pose(int i, const RigidPose& pose);
  /// Simulated time at the end of the last frame, s.
  double time() const { return m_time; }
  /// Called at the end of every detection/response cycle (after the
  /// response; rolled-back cycles included) with the World, for
  /// measurements inside frames (e.g. each cycle's query answers against an
  /// unlimited query, bench_realtime --lod). Its time counts in the frame's
  /// wall time, in no stage. Empty: none.
  void set_cycle_observer(std::function<void(const World&)> observer) {
    m_cycle_observer = std::move(observer);
  }

  /// The last query of each collision pair (same order as plan().pairs).
  const std::vector<collision::CollisionResult>& results() const { return m_results; }
  /// The test budget each pair's last query of the last cycle got (-1: no
  /// test budget; 0: not queried), same order as plan().pairs.
  const std::vector<int64_t>& pair_test_budgets() const { return m_pair_tests; }

  /// Advances one frame of 1 / frame_rate simulated seconds with the
  /// settings' query budget (in real-time mode: what is left of the frame).
  FrameMetrics step();
  /// As step(), with a time budget of `budget_seconds` (> 0, infinity for
  /// none) per query in place of the settings' (and of real-time mode's).
  FrameMetrics step(double budget_seconds);

  /// One object that runs a frame's cycles: its cost of one FEM sub-step
  /// (any unit, e.g. its tets) and its sub-step over a long interval, s.
  struct CycleLoad {
    double cost = 1;
    double step = 0;
  };
  /// The cycle count for a frame of dt (s) that needs at least n cycles (for
  /// a stable penalty, or for motion): the n' in [n, n + n / 2 + 2] (at most
  /// kMaxMotionCycles) with the least work. Each cycle advances an object in
  /// ceil(h / step) equal sub-steps (h = dt / n'), so a cycle just longer than
  /// an object's sub-step costs it two: 64 cycles of a 16.7 ms frame cost an
  /// object with a 0.256 ms sub-step 128 sub-steps, 68 cycles cost it 68.
  /// Work of n' cycles: sum over loads of cost x n' x (ceil(h / (step (1 -
  /// kStepMargin))) + kCycleOverhead). n itself when no load has a step yet.
  static int fit_cycles(double dt, int n, const std::vector<CycleLoad>& loads);
  /// A cycle is fitted to kStepMargin below an object's sub-step: its stable
  /// step is re-estimated within the frame (a squeezed object stiffens).
  static constexpr double kStepMargin = 0.03;
  /// Fixed cost of one cycle of one object, in its sub-steps: its advance()
  /// ends with a full health check (an element pass, ~1/4 of an RK4 step),
  /// and it updates its spheres and is queried.
  static constexpr double kCycleOverhead = 0.3;
  /// Most cycles a frame is cut into for motion (fast objects).
  static constexpr int kMaxMotionCycles = 1024;

  /// Net energy a contact episode may give the objects with collision.passive,
  /// as a fraction of their kinetic energy when it began (the explicit
  /// penalty's own small gain, ~0.4% per bounce, stays untouched).
  static constexpr double kPassiveTolerance = 0.01;

 private:
  using Clock = std::chrono::steady_clock;
  FrameMetrics advance(std::optional<double> budget_seconds);
  void update_dense(RuntimeObject& o);
  /// The sphere tree of o follows its coarse nodes (rigidly, with its pose,
  /// for a kinematic object).
  void update_spheres(RuntimeObject& o) const;
  /// The sphere tree of deformable object o follows coarse positions x
  /// (#V x 3) in the object's co-rotated frame: x is taken back by its
  /// best-fit rigid motion from the rest nodes (R, t: Kabsch, unweighted),
  /// the spheres are updated there (collision.update) and moved forward by
  /// (R, t). Both update rules measure displacements from the rest nodes, so
  /// without it a spinning object's spheres drift and inflate: in
  /// many_objects a dragon tipped over by the floor turned ~10 degrees per
  /// frame, its root sphere grew from 9.5 to 14 cm within 4 frames, and the
  /// phantom overlaps of the inflated spheres (leaf pairs 24 leaf radii
  /// deep) drove the penalty until the FEM failed its health check.
  void update_deformed_spheres(RuntimeObject& o, const MatX3d& x) const;
  /// Exact reference, frame counter and wall time at the end of step().
  FrameMetrics finish_frame(FrameMetrics& m, Clock::time_point frame_start);
  /// One detection/response cycle of length h (s) inside a frame, ending at
  /// simulated time t_end.
  void cycle(double h, double t_end, double budget, bool last, bool start_free, FrameMetrics& m);
  /// Runs `n` cycles over [t0, t0 + length]; with collision.swept, a cycle
  /// that starts contact-free and asks to be split (m_split) is rolled back
  /// and re-run as shorter cycles (recursively, `depth` deep).
  void run_cycles(double t0, double length, int n, int depth, bool ends_frame,
                  const std::function<double(double)>& budget_at, FrameMetrics& m);
  /// Decides which pairs are queried in every cycle of the coming frame of dt
  /// (m_pair_close: in contact, swept hit, or root spheres closer than twice
  /// the pair's motion over the frame plus one leaf) and which deformable
  /// objects are deferred (RuntimeObject::deferred: in no close pair, not
  /// near an obstacle). Depends on the state only: the same for any thread count.
  void plan_islands(double dt);
  /// collision.budget_split = Priority: each pair's priority weight
  /// (m_pair_weight) and m_query_pairs in the order they share the pool
  /// (lowest priority first); Cheapest: m_query_pairs by their estimated
  /// complete cost (m_pair_cost_tests, cheapest first, unknown last); Even:
  /// weights 1, order unchanged.
  void share_budget();
  /// Budget of a query of BudgetSplit::Cheapest (tests or seconds): `pool`
  /// is what is left of the cycle's pool, `left` the pairs still to query
  /// (this one included), `floor` what each later pair keeps at least, `cost`
  /// the pair's estimated complete cost. A pair whose estimate fits, with the
  /// later pairs' floors set aside, gets what is left of the pool but at most
  /// twice its estimate (or the even share of what is left, if more); else
  /// the even share of what is left. Never more than pool - (left - 1) floor.
  static double cheapest_budget(double pool, double left, double floor, double cost);
  /// Each pair's cost of its last complete query, in tests and seconds, or
  /// after an interrupted one at least what it used (+ 1 test); inf: never
  /// queried. The estimate of BudgetSplit::Cheapest.
  std::vector<double> m_pair_cost_tests, m_pair_cost_seconds;
  std::vector<double> m_pair_weight;   ///< priority weight of each pair this cycle
  std::vector<size_t> m_query_pairs;   ///< pairs that need a traversal this cycle
  std::vector<double> m_pair_budget;   ///< their time budgets this cycle, s
  std::vector<int64_t> m_pair_tests;   ///< their test budgets this cycle (-1: none)
  std::vector<double> m_pair_depth;    ///< deepest penetration of each pair's last response, m
  /// Lightest lumped node mass of the deformable objects in close pairs this
  /// frame (plan_islands; m_min_node_mass before it runs), kg.
  double m_close_min_mass = 1;
  /// Per pair: queried in every cycle of the frame (else only in its last).
  std::vector<char> m_pair_close;
  /// Cycles a frame of dt needs so that no pair moves more than
  /// collision.cycle_motion leaf radii relative to each other per cycle,
  /// from each object's last measured sphere speed; near static obstacles,
  /// also as many as keep each object's approach to them under
  /// kObstacleStep per cycle (obstacle_approach). pairs_only: the pairs'
  /// bound alone.
  int motion_cycles(double dt, bool pairs_only = false) const;
  /// fit_cycles for the frame of dt: the deformable objects that run the
  /// cycles (not deferred), each weighted by its tets, at its step_cap.
  int aligned_cycles(double dt, int n) const;
  /// Largest node displacement of scripted object o over the next dt, m.
  double scripted_motion(const RuntimeObject& o, double dt) const;
  /// Spheres at the current (actual) positions: start of the next sweep.
  void reset_sweep_start();
  /// Projects object o's dense surface out of the static obstacles (see
  /// coupling/obstacle.hpp); [lo, hi] bounds its coarse nodes over the
  /// cycle. Sets o.near_obstacle when it came within reach of one, and
  /// o.cycle_obstacle_vertices / depth. Touches object o only (runs on its worker).
  /// `support_work` is the work the support did in the cycle (J): with the
  /// projection's energy change, what they added is taken back from the
  /// object's kinetic energy (the obstacles are never a source of energy).
  void resolve_obstacles(RuntimeObject& o, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                         double support_work) const;
  /// Sets o.obstacle_support for the coming cycle (its FEM loads, without
  /// the support, already set on o.sim): on each coarse node of a dense
  /// vertex touching an obstacle (within kObstacleContact of it), the
  /// obstacle pushes back the inward normal part of the node's total force,
  /// so resting nodes do not accelerate into it and the projection after
  /// the cycle has (almost) nothing to do. Frictionless and unilateral.
  /// Returns whether any node is supported. Touches object o only.
  bool obstacle_support(RuntimeObject& o) const;
  /// The dense vertices of o that may lie closer than `threshold` (m) to one
  /// of the obstacles o.obstacle_near at o.positions: their indices in
  /// o.obstacle_layer, their positions (the links of their
  /// triples evaluated, LinkEvaluator::apply_triples) in o.obstacle_dense.
  /// The vertices come in triple order, not ascending.
  /// A triple is skipped when a lower bound of the signed distance of its
  /// vertices (from its nodes' coordinates in the obstacle's frame, each
  /// vertex being within triple_reach of a convex combination of them) is
  /// at least the threshold; in the triples kept, a vertex is skipped when
  /// the same bound from its own origin (its weights applied to the nodes'
  /// coordinates) and its own link length is. So the skipped vertices are
  /// exactly ones the callers would have found too far: the same results,
  /// bitwise, as testing every vertex (WorldSettings::obstacle_cull = false).
  /// Only the layer's vertices are evaluated (LinkEvaluator::apply_links).
  /// With same_triples: the last call's layer, evaluated at the current
  /// positions (for a caller that knows the nodes have not moved enough to
  /// change it).
  void obstacle_layer(RuntimeObject& o, double threshold, bool same_triples = false) const;
  /// How fast object o's dense surface may approach the static obstacles
  /// over the coming frame of dt, m/s: per link triple that could reach an
  /// obstacle within the frame at its nodes' speeds, the fastest of its
  /// nodes' velocity components toward that obstacle along the axis that
  /// bounds the triple's distance (a lower bound of the signed distance,
  /// as in obstacle_layer, decreases no faster than that); the largest over
  /// triples, and at least the penetration speed its last cycle's projection
  /// measured (RuntimeObject::obstacle_rate: what the velocities at the
  /// frame's start do not show, e.g. an acceleration into the obstacle).
  /// A node vibrating along the floor, or fast far from any obstacle, sets
  /// no cycles; its speed into the floor does.
  double obstacle_approach(const RuntimeObject& o, double dt) const;
  /// Some object came within reach of an obstacle in the last cycle.
  bool m_obstacle_near = false;
  /// Detection/response cycles a frame of dt needs for a stable penalty.
  int contact_cycles(double dt) const;
  /// True when the last queries reported no pair at all (every pair pruned:
  /// the covered surfaces are apart).
  bool contact_free() const;
  /// For a frame of dt that starts contact-free (collision.swept): would the
  /// single-cycle trial find a contact? Each pair whose root spheres are
  /// within reach is swept from its current spheres to the spheres at the
  /// nodes moved on with their velocities over the stretch the trial sweeps
  /// (dt, plus dt / 2 with collision.midpoint), as the trial's sweep would
  /// with a motion that keeps its velocities. True when one touches: the
  /// frame then runs in cycles at once instead of paying for a trial it
  /// would roll back (the first contact frame of the main job: 70 of its
  /// 147-199 sub-steps). Only deformable and static objects are predicted
  /// (a scripted object's pair answers false: the trial decides). A wrong
  /// answer costs time, never a contact: false runs the trial as before,
  /// true cycles a frame that stays apart. Leaves the spheres as they were;
  /// sets the predicted objects' speed (RuntimeObject::speed) from the
  /// motion, as the trial would. Serial, in pair order: any thread count.
  /// Not before the objects have advanced once (their sub-steps, which size
  /// the cycles, are not known yet): a World's first frame takes the trial.
  bool contact_ahead(double dt);
  /// Scratch of contact_ahead: the spheres of each object before, predicted
  /// and swept.
  std::vector<std::vector<collision::Sphere>> m_ahead_saved;
  std::vector<std::vector<collision::SweptSphere>> m_ahead_swept;
  std::vector<char> m_ahead_done;
  std::vector<double> m_ahead_motion;
  /// State a rolled-back frame returns to.
  struct Snapshot {
    std::vector<MatX3d> positions, velocities;
    std::vector<RigidPose> poses;
    std::vector<std::vector<collision::NodePair>> fronts;
    std::vector<collision::CollisionResult> complete;
    std::vector<double> complete_time, complete_depth, obstacle_debt;
    std::vector<MatX3d> obstacle_support;
    std::vector<char> near_obstacle;
    double node_stiffness = 0;
    double contact_scale = 1;
    double contact_work = 0, passive_allowance = -1;
    std::vector<std::vector<collision::Sphere>> start_spheres;
    std::vector<double> lags;
  };
  void save(Snapshot& s) const;
  void restore(const Snapshot& s);

  static constexpr int kMaxContactCycles = 64;
  /// Deepest recursive split of a cycle (each split at most kMaxSplit
  /// cycles); the most cycles for motion is kMaxMotionCycles.
  static constexpr int kMaxSplitDepth = 4;
  static constexpr int kMaxSplit = 64;
  /// Largest motion per cycle of an object near an obstacle, m: each cycle's
  /// projection moves surface nodes at most about this far (an instantaneous
  /// position change stores elastic energy that comes back as a bounce).
  static constexpr double kObstacleStep = 1e-3;
  /// A dense vertex this close to an obstacle (m) is resting on it: its
  /// coarse nodes get the obstacle's support (obstacle_support()).
  static constexpr double kObstacleContact = 1e-4;
  /// How much farther than asked obstacle_layer lists triples, m: the list
  /// stands until a node has moved this far.
  static constexpr double kObstacleListMargin = 4e-3;
  /// Longest cycle near an obstacle, s.
  static constexpr double kObstacleCycle = 1e-3;
  /// Runs f(k) for every object index k, on m_threads workers (each object
  /// on one worker; objects are independent, so any assignment gives the
  /// same results). A failure is rethrown after the loop, the first by
  /// object order.
  template <class F>
  void for_each_object(F&& f);
  int m_threads = 1;
  std::vector<int> m_order;  ///< for_each_object: the objects in the order they are handed out
  std::unique_ptr<WorkerPool> m_pool;  ///< the workers (none with 1 thread or 1 object)
  bool m_deadline_warned = false;
  /// Node mass standing for "does not move under contact" (static, rigid objects).
  static constexpr double kImmovableMass = 1e30;
  /// Largest omega h of the staggered penalty (explicit limit 2; smaller
  /// values inject less energy per contact).
  static constexpr double kContactOmegaStep = 0.25;
  /// Largest omega h a response may reach; beyond it (more cycles needed
  /// than kMaxContactCycles, or stiffness jumping within a frame) its forces
  /// are scaled by (kContactOmegaLimit / omega h)^2: a softer but stable penalty.
  static constexpr double kContactOmegaLimit = 1.0;
  /// Scales this cycle's contact forces so the episode stays passive (see
  /// CollisionSpec::passive); h is the cycle length (s).
  void limit_contact_work(double h, FrameMetrics& m);

  WorldSettings m_settings;
  StagePlan m_plan;
  std::vector<RuntimeObject> m_objects;
  std::vector<collision::CollisionResult> m_results;
  std::vector<std::vector<collision::NodePair>> m_fronts;
  /// Last complete (not interrupted) answer of each pair and its simulated time.
  std::vector<collision::CollisionResult> m_complete;
  std::vector<double> m_complete_time;
  /// Deepest penetration of the response to each pair's last complete answer
  /// (0: it had no contact), m: caps untested pairs once that answer is too old.
  std::vector<double> m_complete_depth;
  double m_min_node_mass = 1;   ///< lightest lumped node mass of the deformable objects, kg
  double m_node_stiffness = 0;  ///< largest per-node penalty stiffness of the last response, N/m
  /// Squared frequency bound of the last response's penalty springs, 1/s^2:
  /// the largest over responding pairs of the two sides' largest node rates
  /// (k share / m, summed over all pairs).
  double m_contact_rate = 0;
  /// Per object, per coarse node: the penalty rate over all pairs of this
  /// cycle at the full stiffness (what the node rate cap weighs against) and
  /// as applied, 1/s^2.
  std::vector<Eigen::VectorXd> m_total_rate, m_applied_rate;
  double m_penalty_energy = 0;  ///< penalty spring energy of the last response, J
  double m_contact_scale = 1;   ///< softening of the current contact episode (1: none)
  /// Work done by the contact forces on the deformable objects since the
  /// contact episode began, J (collision.passive).
  double m_contact_work = 0;
  /// Net energy the current episode may add, J (-1: no episode under way).
  double m_passive_allowance = -1;
  Snapshot m_snapshot;  ///< reused storage for the single-cycle trial
  std::vector<Snapshot> m_split_snapshots;  ///< per split depth (collision.swept)
  /// Set by cycle(): the cycle should be re-run as m_split_factor shorter cycles.
  bool m_split = false;
  int m_split_factor = 1;
  /// Median leaf radius of each pair's smaller tree (same order as plan().pairs), m.
  std::vector<double> m_pair_leaf;
  std::vector<collision::NodePair> m_sweep_stack;  ///< reused storage of the swept queries
  /// Per pair: the swept query of the last cycle reported a pair.
  std::vector<char> m_swept_hit;
  std::function<void(const World&)> m_cycle_observer;
  std::vector<double> m_object_energy;  ///< per-object mechanical energy (finish_frame scratch)
  int m_frame = 0;
  double m_time = 0;
};

}  // namespace icd::coupling
