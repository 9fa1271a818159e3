#include <icd/coupling/world.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

#include <Eigen/SVD>

#include <icd/collision/aabb_tree.hpp>
#include <icd/collision/sphere_update.hpp>
#include <icd/collision/swept_spheres.hpp>
#include <icd/coupling/contact_response.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

using Clock = std::chrono::steady_clock;

// collision.cycles_at_fem_step applies when the frame's motion bound
// (World::motion_cycles) times this is at most the sub-step count: each pair
// closes at most cycle_motion / kSlowContact leaf radii per cycle.
constexpr int kSlowContact = 3;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Kinetic + elastic + gravity potential (J). Not fem::Simulator::total_energy(),
// which also counts -f_ext . x for the external (here: contact) forces: a
// penalty force is not a constant load, and that term depends on the origin.
double mechanical_energy(fem::Simulator& sim, const Eigen::Vector3d& gravity) {
  const fem::Model& model = sim.model();
  const MatX3d& x = sim.positions();
  return model.kinetic_energy(sim.velocities()) + sim.model().elastic().energy(x) -
         (x.transpose() * model.mass()).dot(gravity);
}

// Runs `f` and returns its result; a failure it reports gets who() (e.g.
// `object "left"`) in front of its message, keeping its type.
template <class W, class F>
auto prefixing_failures(W&& who, F&& f) {
  try {
    return f();
  } catch (const NumericalError& e) {
    throw NumericalError(who() + ": " + e.what());
  } catch (const InputError& e) {
    throw InputError(who() + ": " + e.what());
  } catch (const ParameterError& e) {
    throw ParameterError(who() + ": " + e.what());
  }
}

// The failures of object `o` (FEM) and of the contact between `a` and `b`.
template <class F>
auto naming(const RuntimeObject& o, F&& f) {
  return prefixing_failures([&] { return "object \"" + o.setup.name + "\""; }, std::forward<F>(f));
}
template <class F>
auto naming(const RuntimeObject& a, const RuntimeObject& b, F&& f) {
  return prefixing_failures(
      [&] { return "objects \"" + a.setup.name + "\" and \"" + b.setup.name + "\""; },
      std::forward<F>(f));
}

}  // namespace

template <class F>
void World::for_each_object(F&& f) {
  const int n = static_cast<int>(m_objects.size());
  if (!m_pool || n <= 1) {
    for (int k = 0; k < n; ++k) f(k);
    return;
  }
  std::vector<std::exception_ptr> errors(static_cast<size_t>(n));
  // Objects differ in cost: each worker takes the next object; each
  // object's work is the same on any worker, so no result depends on it.
  // The costliest first (by its time in the last cycle; ties in object
  // order): the calling thread takes the first at once, while a parked
  // worker is still waking up, so the wake-up delays the cheaper object.
  m_order.resize(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) m_order[static_cast<size_t>(k)] = k;
  const auto cost = [&](int k) {
    const RuntimeObject& o = m_objects[static_cast<size_t>(k)];
    return o.stage_seconds[0] + o.stage_seconds[1] + o.stage_seconds[2];
  };
  std::stable_sort(m_order.begin(), m_order.end(), [&](int x, int y) { return cost(x) > cost(y); });
  m_pool->run(n, [&](int q) {
    const int k = m_order[static_cast<size_t>(q)];
    try {
      f(k);
    } catch (...) {
      errors[static_cast<size_t>(k)] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

World::World(std::vector<WorldObject> objects, WorldSettings settings)
    : m_settings(std::move(settings)) {
  validate(m_settings);
  std::vector<ObjectSetup> setups;
  setups.reserve(objects.size());
  for (const WorldObject& w : objects) setups.push_back(w.setup);
  m_plan = make_plan(setups, m_settings);
  m_threads = m_settings.threads > 0
                  ? m_settings.threads
                  : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (m_threads > 1 && objects.size() > 1)
    m_pool = std::make_unique<WorkerPool>(std::min<int>(m_threads, static_cast<int>(objects.size())),
                                          m_settings.worker_spin);
  const CollisionSpec& cs = m_settings.collision;
  m_objects.reserve(objects.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    RuntimeObject o;
    o.setup = std::move(objects[i].setup);
    o.plan = m_plan.objects[i];
    o.asset = std::move(objects[i].asset);
    if (o.plan.sphere_tree && o.asset.spheres.num_nodes() == 0)
      throw InputError("object \"" + o.setup.name + "\": takes part in collisions but has no sphere tree");
    // No tree levels deeper than the queries can reach.
    if (o.plan.sphere_tree && m_plan.tree_cut != TreeCut::None)
      collision::truncate_levels(o.asset.spheres, m_plan.max_tree_level);
    // Static objects are never updated: make their trees layered once here.
    if (cs.layered) collision::enclose_children(o.asset.spheres);
    o.rest = o.asset.coarse.V;
    o.positions = o.rest;
    if (o.plan.kinematic && o.setup.motion) {  // a scripted object starts at its pose at t = 0
      o.pose = o.setup.motion(0);
      o.positions = (o.rest * o.pose.rotation.toRotationMatrix().transpose()).rowwise() +
                    o.pose.translation.transpose();
    }
    o.contact_forces = MatX3d::Zero(o.rest.rows(), 3);
    if (o.plan.fem) {
      fem::ModelOptions mo;
      mo.damping = o.setup.damping;
      mo.gravity = m_settings.gravity;
      mo.mass_scaling.target_ratio = o.setup.mass_scaling_target;
      fem::Model model =
          naming(o, [&] { return fem::Model(o.rest, o.asset.coarse.T, o.setup.material, mo); });
      for (int n : o.setup.fixed_nodes)
        if (n < 0 || n >= model.num_nodes())
          throw InputError("object \"" + o.setup.name + "\": fixed node " + std::to_string(n) +
                           " out of range (the coarse mesh has " +
                           std::to_string(model.num_nodes()) + " nodes)");
      model.set_fixed_nodes(o.setup.fixed_nodes);
      fem::SimulatorOptions so;
      so.integrator = o.setup.integrator;
      so.max_step = 1.0 / m_settings.frame_rate;
      so.frequency_reuse_time = 1.0 / m_settings.frame_rate;  // one estimate per frame
      if (m_plan.response) so.frequency.contact_stiffness = cs.contact.stiffness;
      o.sim = naming(o, [&] { return std::make_unique<fem::Simulator>(std::move(model), so); });
      MatX3d v(o.rest.rows(), 3);
      v.rowwise() = o.setup.velocity.transpose();
      for (int n : o.setup.fixed_nodes) v.row(n).setZero();
      o.sim->set_velocities(v);
    }
    if (o.plan.dense_update) {
      o.dense = o.asset.dense.V;
      o.links = LinkEvaluator(o.asset.links);
    }
    m_objects.push_back(std::move(o));
  }
  // Node masses for the mass-weighted response; objects without FEM never
  // move under contact: infinite mass for the stability estimate.
  for (RuntimeObject& o : m_objects)
    o.node_mass =
        o.sim ? o.sim->model().mass() : Eigen::VectorXd::Constant(o.rest.rows(), kImmovableMass);
  // Fewer deformable objects than threads: the force loops split too
  // (bitwise identical for any count, fem::ForceOptions::num_threads).
  int deformable = 0;
  for (const RuntimeObject& o : m_objects) deformable += o.sim ? 1 : 0;
  if (deformable > 0 && deformable < m_threads)
    for (RuntimeObject& o : m_objects)
      if (o.sim) o.sim->model().elastic().set_num_threads(m_threads / deformable);
  m_min_node_mass = std::numeric_limits<double>::infinity();
  for (const RuntimeObject& o : m_objects)
    if (o.sim) m_min_node_mass = std::min(m_min_node_mass, o.node_mass.minCoeff());
  m_close_min_mass = m_min_node_mass;
  m_results.resize(m_plan.pairs.size());
  m_fronts.resize(m_plan.pairs.size());
  m_complete.resize(m_plan.pairs.size());
  m_complete_time.assign(m_plan.pairs.size(), -std::numeric_limits<double>::infinity());
  m_complete_depth.assign(m_plan.pairs.size(), 0.0);
  m_swept_hit.assign(m_plan.pairs.size(), 0);
  m_pair_close.assign(m_plan.pairs.size(), 1);
  m_pair_budget.assign(m_plan.pairs.size(), 0.0);
  m_pair_tests.assign(m_plan.pairs.size(), 0);
  m_pair_depth.assign(m_plan.pairs.size(), 0.0);
  m_pair_weight.assign(m_plan.pairs.size(), 1.0);
  m_pair_cost_tests.assign(m_plan.pairs.size(), std::numeric_limits<double>::infinity());
  m_pair_cost_seconds.assign(m_plan.pairs.size(), std::numeric_limits<double>::infinity());
  for (const RuntimeObject& o : m_objects)
    if (!(o.setup.collision_weight > 0) || !std::isfinite(o.setup.collision_weight))
      throw ParameterError("object \"" + o.setup.name + "\": collision_weight must be > 0 and finite, got " +
                           std::to_string(o.setup.collision_weight));
  for (size_t k = 0; k < m_settings.obstacles.size(); ++k)
    validate(m_settings.obstacles[k], ("obstacles[" + std::to_string(k) + "]").c_str());
  if (!m_settings.obstacles.empty())
    for (RuntimeObject& o : m_objects) {
      if (!o.sim) continue;  // static and kinematic objects move as they are told
      if (o.links.num_links() == 0) o.links = LinkEvaluator(o.asset.links);
      o.max_link = o.asset.links.coeffs.rows() ? o.asset.links.coeffs.rowwise().norm().maxCoeff() : 0;
      // (in triple order, as obstacle_layer walks them)
      o.link_bound.resize(4 * static_cast<size_t>(o.asset.links.num_links()));
      for (size_t j = 0; j < o.links.triple_links().size(); ++j) {
        const int32_t k = o.links.triple_links()[j];
        for (int i = 0; i < 3; ++i) o.link_bound[4 * j + i] = o.asset.links.alpha(k, i);
        o.link_bound[4 * j + 3] = o.asset.links.coeffs.row(k).norm();
      }
      o.triple_reach.assign(static_cast<size_t>(o.links.num_triples()), 0.0);
      for (int t = 0; t < o.links.num_triples(); ++t)
        for (int32_t j = o.links.links_of_triple(t); j < o.links.links_of_triple(t + 1); ++j) {
          const int32_t k = o.links.triple_links()[static_cast<size_t>(j)];
          double& reach = o.triple_reach[static_cast<size_t>(t)];
          if (reach < 0) break;
          reach = o.asset.links.alpha.row(k).minCoeff() < 0
                      ? -1.0
                      : std::max(reach, o.asset.links.coeffs.row(k).norm());
        }
      std::vector<double> leaves;
      const collision::SphereTree& t = o.asset.spheres;
      for (int i = 0; i < t.num_nodes(); ++i)
        if (t.is_leaf(i)) leaves.push_back(t.rest_spheres[i].r);
      if (!leaves.empty()) {
        std::nth_element(leaves.begin(), leaves.begin() + leaves.size() / 2, leaves.end());
        o.obstacle_scale = leaves[leaves.size() / 2];
      } else {
        o.obstacle_scale = 0.05 * (o.rest.colwise().maxCoeff() - o.rest.colwise().minCoeff()).norm();
      }
    }
  for (RuntimeObject& o : m_objects) {
    if (!o.plan.sphere_tree) continue;
    std::vector<double> leaves;
    const collision::SphereTree& t = o.asset.spheres;
    for (int i = 0; i < t.num_nodes(); ++i)
      if (t.is_leaf(i)) leaves.push_back(t.rest_spheres[i].r);
    std::nth_element(leaves.begin(), leaves.begin() + leaves.size() / 2, leaves.end());
    o.leaf_radius = leaves[leaves.size() / 2];
  }
  for (const auto& [i, j] : m_plan.pairs)
    m_pair_leaf.push_back(std::min(m_objects[i].leaf_radius, m_objects[j].leaf_radius));
  reset_sweep_start();
}

void World::reset_sweep_start() {
  if (!m_settings.collision.swept) return;
  for (RuntimeObject& o : m_objects)
    if (o.plan.sphere_update) {
      update_spheres(o);
      if (m_settings.collision.layered) collision::enclose_children(o.asset.spheres);
      o.start_spheres = o.asset.spheres.spheres;
    }
}

void World::plan_islands(double dt) {
  const CollisionSpec& cs = m_settings.collision;
  std::vector<char> active(m_objects.size(), 0);
  for (size_t i = 0; i < m_objects.size(); ++i) {
    const RuntimeObject& o = m_objects[i];
    // Kinematic objects follow their script every cycle (cheap); objects near
    // an obstacle are projected every cycle.
    active[i] = o.plan.kinematic || o.near_obstacle || o.external_forces.size() > 0;
  }
  const double g = 0.5 * m_settings.gravity.norm() * dt * dt;  // (same on both: relative 0)
  // An object that could reach an obstacle within the frame runs the cycles
  // too (advanced over the whole frame at once, a fast or heavily
  // accelerated object would pass through a thin obstacle unseen): its
  // dense surface lies within max_link of the coarse nodes' box, which moves
  // at most 2 * speed * dt + g * dt^2 / 2 over the frame (as for pairs).
  for (size_t i = 0; i < m_objects.size() && !m_settings.obstacles.empty(); ++i) {
    const RuntimeObject& o = m_objects[i];
    if (active[i] || !o.plan.fem) continue;
    const double pad = o.max_link + 2 * o.speed * dt + g;
    const Eigen::Vector3d lo = o.positions.colwise().minCoeff().transpose().array() - pad;
    const Eigen::Vector3d hi = o.positions.colwise().maxCoeff().transpose().array() + pad;
    for (const Obstacle& ob : m_settings.obstacles)
      if (!(ob.lower_bound(lo, hi) > 0)) active[i] = 1;  // (NaN: active)
  }
  for (size_t p = 0; p < m_plan.pairs.size(); ++p) {
    const auto [i, j] = m_plan.pairs[p];
    const RuntimeObject& a = m_objects[i];
    const RuntimeObject& b = m_objects[j];
    const collision::CollisionResult& r = m_results[p];
    bool close = !r.colliding.empty() || !r.untested.empty() || (cs.swept && m_swept_hit[p]);
    if (!close) {
      // Root spheres enclose every sphere (layered trees) or at least the
      // surface; each side moves at most speed * dt over the frame if it
      // keeps its speed: twice that, plus one leaf radius, is the reach.
      const auto speed_of = [&](const RuntimeObject& o) {
        return o.setup.motion && o.plan.kinematic
                   ? std::max(o.speed, scripted_motion(o, dt) / dt)
                   : o.speed;
      };
      const collision::Sphere& ra = a.asset.spheres.spheres[0];
      const collision::Sphere& rb = b.asset.spheres.spheres[0];
      const double gap = (ra.center() - rb.center()).norm() - ra.r - rb.r;
      const double reach = 2 * (speed_of(a) + speed_of(b)) * dt + g + m_pair_leaf[p];
      close = !(gap > reach);  // (NaN: close)
    }
    m_pair_close[p] = close ? 1 : 0;
    if (close) active[i] = active[j] = 1;
  }
  m_close_min_mass = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < m_objects.size(); ++i) {
    m_objects[i].deferred = m_objects[i].plan.fem && !active[i];
    if (m_objects[i].sim && active[i])
      m_close_min_mass = std::min(m_close_min_mass, m_objects[i].node_mass.minCoeff());
  }
}

void World::share_budget() {
  const CollisionSpec& cs = m_settings.collision;
  const size_t n = m_query_pairs.size();
  for (size_t p : m_query_pairs) m_pair_weight[p] = 1;
  if (cs.budget_split == BudgetSplit::Cheapest && n > 1) {
    // Cheapest complete answer first (ties in pair order: deterministic).
    std::stable_sort(m_query_pairs.begin(), m_query_pairs.end(), [&](size_t x, size_t y) {
      return m_pair_cost_tests[x] < m_pair_cost_tests[y];
    });
    return;
  }
  if (cs.budget_split != BudgetSplit::Priority || n < 2) return;
  const double dt = 1.0 / m_settings.frame_rate;
  const auto centre_velocity = [](const RuntimeObject& o) -> Eigen::Vector3d {
    if (o.sim) return o.sim->velocities().colwise().mean().transpose();
    if (o.plan.kinematic && !o.setup.motion) return o.setup.velocity;
    return Eigen::Vector3d::Zero();
  };
  for (size_t p : m_query_pairs) {
    const RuntimeObject& a = m_objects[m_plan.pairs[p].first];
    const RuntimeObject& b = m_objects[m_plan.pairs[p].second];
    const double leaf = std::max(m_pair_leaf[p], 1e-12);
    const Eigen::Vector3d d = (b.positions.colwise().mean() - a.positions.colwise().mean()).transpose();
    const double len = d.norm();
    // Closing speed: how fast the centres approach (0 when they separate).
    const double closing =
        len > 0 ? std::max(0.0, -(centre_velocity(b) - centre_velocity(a)).dot(d / len)) : 0.0;
    double w = a.setup.collision_weight * b.setup.collision_weight *
               (1 + m_pair_depth[p] / leaf + closing * dt / leaf);
    if (!std::isfinite(w)) w = 1;
    m_pair_weight[p] = w;
  }
  // Lowest priority first: what a pair leaves of its share goes to the
  // pairs after it (ties in pair order: deterministic).
  std::stable_sort(m_query_pairs.begin(), m_query_pairs.end(),
                   [&](size_t x, size_t y) { return m_pair_weight[x] < m_pair_weight[y]; });
}

double World::cheapest_budget(double pool, double left, double floor, double cost) {
  const double spare = pool - (left - 1) * floor;  // what the later pairs' floors leave
  const double even = pool / left;
  if (cost <= spare) return std::min(spare, std::max(2 * cost, even));
  return std::min(spare, even);
}

int World::motion_cycles(double dt, bool pairs_only) const {
  double cycles = 1;
  if (m_obstacle_near && !pairs_only) {
    // Near an obstacle: each object moves at most cycle_motion of its scale
    // (and of half the thinnest box) per cycle, gravity included.
    // and a cycle is at most kObstacleCycle long: the support of a resting
    // node is held over the cycle (the energy its error adds is taken back
    // from the motion, see resolve_obstacles; a short cycle keeps it small).
    cycles = std::max(cycles, std::ceil(dt / kObstacleCycle));
    double thin = std::numeric_limits<double>::infinity();
    for (const Obstacle& ob : m_settings.obstacles) thin = std::min(thin, 0.5 * ob.thickness());
    for (const RuntimeObject& o : m_objects) {
      // (the objects that came near one or may reach one within the frame:
      // obstacle_approach is 0 for the others)
      if (!o.sim || o.obstacle_scale <= 0 || o.deferred) continue;
      // How far the surface may sink into an obstacle over the frame: its
      // approach (not the speed of nodes moving along or away from it).
      const double v = obstacle_approach(o, dt);
      const double motion = v * dt + 0.5 * m_settings.gravity.norm() * dt * dt;
      const double step =
          std::min(m_settings.collision.cycle_motion * std::min(o.obstacle_scale, thin), kObstacleStep);
      cycles = std::max(cycles, std::ceil(motion / step));
    }
  }
  if (!m_settings.collision.swept) return static_cast<int>(std::min<double>(cycles, kMaxMotionCycles));
  // Scripted objects: their speed over the coming frame, from their motion
  // (the last cycle's speed may predate a keyframe).
  std::vector<double> speed(m_objects.size());
  for (size_t i = 0; i < m_objects.size(); ++i)
    speed[i] = m_objects[i].setup.motion && m_objects[i].plan.kinematic
                   ? std::max(m_objects[i].speed, scripted_motion(m_objects[i], dt) / dt)
                   : m_objects[i].speed;
  for (size_t p = 0; p < m_plan.pairs.size(); ++p) {
    if (!m_pair_close[p]) continue;  // queried once, at the frame's end (plan_islands)
    const auto [i, j] = m_plan.pairs[p];
    const double motion = (speed[i] + speed[j]) * dt;
    const double step = m_settings.collision.cycle_motion * m_pair_leaf[p];
    if (step > 0) cycles = std::max(cycles, std::ceil(motion / step));
  }
  return static_cast<int>(std::min<double>(cycles, kMaxMotionCycles));
}

double World::obstacle_approach(const RuntimeObject& o, double dt) const {
  const MatX3d& v = o.sim->velocities();
  const Eigen::VectorXd speed = v.rowwise().norm();
  const double fall = 0.5 * m_settings.gravity.norm() * dt * dt;
  double approach = o.near_obstacle ? o.obstacle_rate : 0.0;
  // The obstacles any vertex may reach within the frame at the fastest
  // node's speed (the surface lies within max_link of the nodes' box).
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(speed.maxCoeff() * dt + fall + o.max_link);
  const Eigen::Vector3d lo = o.positions.colwise().minCoeff().transpose() - pad;
  const Eigen::Vector3d hi = o.positions.colwise().maxCoeff().transpose() + pad;
  const int n = static_cast<int>(o.positions.rows());
  MatX3d q, w;  // node coordinates and velocities in the obstacle's frame
  for (const Obstacle& ob : m_settings.obstacles) {
    if (ob.lower_bound(lo, hi) > 0) continue;
    const bool plane = ob.type == Obstacle::Type::Plane;
    if (plane) {
      q.resize(n, 3);  // (column 0 only)
      w.resize(n, 3);
      q.col(0) = (o.positions.rowwise() - ob.point.transpose()) * ob.normal;
      w.col(0) = v * ob.normal;
    } else {
      q = (o.positions.rowwise() - ob.point.transpose()) * ob.axes;
      w = v * ob.axes;
    }
    for (int t = 0; t < o.links.num_triples(); ++t) {
      const int32_t* nodes = o.links.triple_nodes(t);
      const double r = o.triple_reach[static_cast<size_t>(t)];
      // The lower bound of its vertices' signed distance (obstacle_layer):
      // bound_k - reach on its binding axis k, the side s the triple is on.
      int axis = 0;
      double side = 1, bound = -std::numeric_limits<double>::infinity();
      for (int k = 0; k < (plane ? 1 : 3); ++k) {
        const double a = std::min({q(nodes[0], k), q(nodes[1], k), q(nodes[2], k)});
        const double b = -std::max({q(nodes[0], k), q(nodes[1], k), q(nodes[2], k)});
        const double f = plane ? a : std::max(a, b) - ob.half_extents[k];
        if (f > bound || k == 0) {
          bound = f;
          axis = k;
          side = plane || a >= b ? 1.0 : -1.0;
        }
      }
      bound -= r < 0 ? o.max_link : r;
      const double vt = std::max({speed[nodes[0]], speed[nodes[1]], speed[nodes[2]]});
      // Out of reach for the frame at its own speed: max_k f_k decreases no
      // faster than f_axis, whose decrease is its nodes' motion toward the
      // obstacle along the axis (at most vt per second).
      if (bound > vt * dt + fall + 1e-9) continue;  // (NaN: counted)
      for (int i = 0; i < 3; ++i) approach = std::max(approach, -side * w(nodes[i], axis));
    }
  }
  return approach;
}

int World::fit_cycles(double dt, int n, const std::vector<CycleLoad>& loads) {
  n = std::clamp(n, 1, kMaxMotionCycles);
  const auto work = [&](int c) {
    const double h = dt / c;
    double w = 0;
    for (const CycleLoad& l : loads) {
      const double sub = std::ceil(h / (l.step * (1 - kStepMargin)) * (1 - 1e-12));
      w += l.cost * c * (std::max(sub, 1.0) + kCycleOverhead);
    }
    return w;
  };
  for (const CycleLoad& l : loads)
    if (!(l.step > 0) || !std::isfinite(l.step) || !(l.cost > 0)) return n;  // nothing to fit
  if (loads.empty()) return n;
  // Beyond ~1.5 n the overhead of the extra cycles exceeds what they save.
  const int last = std::min(kMaxMotionCycles, n + n / 2 + 2);
  int best_n = n;
  double best = work(n);
  for (int c = n + 1; c <= last; ++c) {
    const double w = work(c);
    if (w < best) {
      best = w;
      best_n = c;
    }
  }
  return best_n;
}

int World::aligned_cycles(double dt, int n) const {
  std::vector<CycleLoad> loads;
  for (const RuntimeObject& o : m_objects) {
    if (!o.sim || o.deferred) continue;  // a deferred object advances once, whatever n is
    loads.push_back({static_cast<double>(o.asset.coarse.T.rows()), o.step_cap});
  }
  return fit_cycles(dt, n, loads);
}

void World::set_external_forces(int i, const MatX3d& forces) {
  if (i < 0 || i >= static_cast<int>(m_objects.size()))
    throw ParameterError("World::set_external_forces: no object " + std::to_string(i));
  RuntimeObject& o = m_objects[static_cast<size_t>(i)];
  if (forces.size() > 0 && forces.rows() != o.rest.rows())
    throw ParameterError("object \"" + o.setup.name + "\": external forces need " +
                         std::to_string(o.rest.rows()) + " rows (one per coarse node), got " +
                         std::to_string(forces.rows()));
  if (!forces.allFinite())
    throw ParameterError("object \"" + o.setup.name + "\": external forces must be finite");
  o.external_forces = forces;
  if (forces.size() == 0 && o.sim) o.sim->set_external_forces(MatX3d::Zero(o.rest.rows(), 3));
}

double World::scripted_motion(const RuntimeObject& o, double dt) const {
  // Largest node displacement over [m_time, m_time + dt], sampled at 8
  // points (a keyframe inside the frame bends the path).
  constexpr int kSamples = 8;
  double d = 0;
  MatX3d prev = o.positions;
  for (int s = 1; s <= kSamples; ++s) {
    const RigidPose p = o.setup.motion(m_time + dt * s / kSamples);
    const MatX3d x = (o.rest * p.rotation.toRotationMatrix().transpose()).rowwise() +
                     p.translation.transpose();
    d += (x - prev).rowwise().norm().maxCoeff();
    prev = x;
  }
  return d;
}

void World::set_kinematic_motion(int i, MotionFunction motion) {
  if (i < 0 || i >= static_cast<int>(m_objects.size()))
    throw ParameterError("World::set_kinematic_motion: no object " + std::to_string(i));
  RuntimeObject& o = m_objects[static_cast<size_t>(i)];
  if (!o.plan.kinematic)
    throw ParameterError("object \"" + o.setup.name +
                         "\": only a rigid (kinematic) object can be scripted");
  o.setup.motion = std::move(motion);
}

void World::set_kinematic_pose(int i, const RigidPose& pose) {
  if (!pose.translation.allFinite() || !std::isfinite(pose.rotation.norm()) ||
      !(pose.rotation.norm() > 0))
    throw ParameterError("World::set_kinematic_pose: the pose must be finite, with a non-zero quaternion");
  const RigidPose from = i >= 0 && i < static_cast<int>(m_objects.size())
                             ? m_objects[static_cast<size_t>(i)].pose
                             : RigidPose{};
  RigidPose to = pose;
  to.rotation.normalize();
  const double t0 = m_time, t1 = m_time + 1.0 / m_settings.frame_rate;
  set_kinematic_motion(i, [from, to, t0, t1](double t) {
    const double s = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
    RigidPose p;
    p.translation = (1 - s) * from.translation + s * to.translation;
    p.rotation = from.rotation.slerp(s, to.rotation);
    return p;
  });
}

int World::contact_cycles(double dt) const {
  if (!m_plan.response) return 1;
  // Conservative: the largest node stiffness (at least k) on the lightest
  // node, every frame. (ContactStats::max_rate, per node k share / m, gave
  // ~4x fewer cycles but let a head-on bounce gain ~15% energy, left for
  // study. Frames that start apart are tried as one cycle in step(), with a
  // rollback when they end in contact.)
  const CollisionSpec& cs = m_settings.collision;
  const double k = std::max(m_node_stiffness, cs.contact.stiffness);
  // (the lightest node of the objects in close pairs once plan_islands has
  // run this frame: an object far from every contact sets no cycle count)
  const double omega = std::sqrt(k / m_close_min_mass);
  const int stiff = std::clamp(static_cast<int>(std::ceil(omega * dt / kContactOmegaStep)), 1,
                               kMaxContactCycles);
  if (!(cs.node_rate_cap && cs.cycles_at_fem_step)) return stiff;
  // With the cap every node's penalty rate stays at 0.45 (kContactOmegaLimit
  // / h)^2 per object whatever h is, so the staggered penalty is stable at
  // any cycle length: the cycles need not be shorter than the FEM sub-step
  // of the objects that run them (each cycle then costs each object one
  // sub-step, none is wasted). On the main job's light nodes the rule above
  // gave 64 cycles (its maximum) in every contact frame, two per sub-step.
  double step = std::numeric_limits<double>::infinity();
  for (const RuntimeObject& o : m_objects)
    if (o.sim && !o.deferred && o.step_cap > 0) step = std::min(step, o.step_cap);
  if (!std::isfinite(step)) return stiff;
  const int at_step = static_cast<int>(std::ceil(dt / (step * (1 - kStepMargin)) * (1 - 1e-12)));
  // Only for slow contacts: with the cap the penalty is softer the longer
  // the cycle, and a fast impact then sinks deeper before it is stopped
  // (Tunnelling.HeadOnContactHoldsAndGainsNoEnergy: balls at 5 m/s each
  // reached 2.59 leaf radii at these cycles, 1.2-1.6 at the rule above). So
  // each pair must close by at most cycle_motion / kSlowContact leaf radii
  // per cycle at this count (the main job: ~0.05 leaf radii per cycle).
  // (the pairs' motion only: the obstacles' cycles bound the projection
  // step, not how fast a pair closes)
  if (kSlowContact * motion_cycles(dt, /*pairs_only=*/true) > at_step) return stiff;
  return std::clamp(at_step, 1, stiff);
}

void World::update_spheres(RuntimeObject& o) const {
  if (o.plan.kinematic) {
    // Rigid motion: the rest spheres move with the pose, radii unchanged
    // (the paper's ratio update is meant for deformation; under a rotation
    // its centre, moved by the mean node displacement, drifts and the ratio
    // of nodes near the centre inflates the radius).
    const Eigen::Matrix3d r = o.pose.rotation.toRotationMatrix();
    collision::SphereTree& t = o.asset.spheres;
    for (size_t k = 0; k < t.spheres.size(); ++k) {
      const collision::Sphere& s0 = t.rest_spheres[k];
      const Eigen::Vector3d c = r * s0.center() + o.pose.translation;
      t.spheres[k] = {c.x(), c.y(), c.z(), s0.r + m_settings.collision.update.margin};
    }
    return;
  }
  update_deformed_spheres(o, o.positions);
}

void World::update_deformed_spheres(RuntimeObject& o, const MatX3d& x) const {
  // Best-fit rotation R of the centred nodes (Kabsch): x - c1 ~ R (X - c0).
  const Eigen::RowVector3d c0 = o.rest.colwise().mean();
  const Eigen::RowVector3d c1 = x.colwise().mean();
  const Eigen::Matrix3d h = (o.rest.rowwise() - c0).transpose() * (x.rowwise() - c1);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  Eigen::Matrix3d r = svd.matrixV() * d * svd.matrixU().transpose();
  if (!r.allFinite()) r.setIdentity();  // (a non-finite state fails in update_spheres)
  // Rows: R^T (x - c1) + c0 is (x - c1) R + c0.
  o.corotated = (x.rowwise() - c1) * r;
  o.corotated.rowwise() += c0;
  collision::update_spheres(o.asset.spheres, o.rest, o.corotated, m_settings.collision.update);
  for (collision::Sphere& s : o.asset.spheres.spheres) {
    const Eigen::Vector3d c = r * (s.center() - c0.transpose()) + c1.transpose();
    s.x = c.x();
    s.y = c.y();
    s.z = c.z();
  }
}

void World::update_dense(RuntimeObject& o) {
  if (o.dense.rows() != o.asset.dense.V.rows()) o.dense.resize(o.asset.dense.V.rows(), 3);
  o.links.apply(o.positions, o.dense);
}

void World::cycle(double h, double t_end, double budget, bool last, bool start_free,
                  FrameMetrics& m) {
  Clock::time_point t0 = Clock::now();
  // 1. Deformation: FEM for deformable objects (with last frame's contact
  //    forces), rigid motion for kinematic ones; then out of the obstacles.
  //    Objects are independent here: one worker each (for_each_object).
  const bool obstacles = !m_settings.obstacles.empty();
  if (obstacles) m_obstacle_near = false;
  if (last) m.obstacle_vertices = 0;
  const bool track_work = m_plan.response && m_settings.collision.passive && m_passive_allowance >= 0;
  // (Stages 1-3 of an object run in one task on its worker, one hand-off
  // per cycle: see the single for_each_object call after stage 3.)
  const auto deform = [&](RuntimeObject& o) {
    const bool was_near = o.near_obstacle;
    o.near_obstacle = false;
    o.cycle_substeps = 0;
    o.cycle_products = 0;
    o.cycle_min_step = std::numeric_limits<double>::infinity();
    o.cycle_obstacle_vertices = 0;
    o.cycle_obstacle_depth = 0;
    o.work_before = o.work_after = 0;
    o.lag += h;
    if (o.deferred && !last) return;  // advances over the whole frame in its last cycle
    // (deferred: it skipped every cycle of the frame but this last one)
    o.advanced = o.deferred ? 1.0 / m_settings.frame_rate : h;
    o.lag = 0;
    if (o.plan.fem) {
      Eigen::Vector3d lo, hi;
      if (obstacles) {
        lo = o.positions.colwise().minCoeff().transpose();
        hi = o.positions.colwise().maxCoeff().transpose();
      }
      const bool supported = o.obstacle_support.size() > 0;
      if (o.external_forces.size() > 0)
        o.sim->set_external_forces(m_plan.response ? MatX3d(o.contact_forces + o.external_forces)
                                                   : o.external_forces);
      else if (m_plan.response)
        o.sim->set_external_forces(o.contact_forces);
      else if (supported)
        o.sim->set_external_forces(MatX3d::Zero(o.rest.rows(), 3));
      if (obstacles && was_near && obstacle_support(o))
        o.sim->set_external_forces(o.sim->model().external_forces() + o.obstacle_support);
      else
        o.obstacle_support.resize(0, 3);
      // The forces are constant over the cycle: their work is f . x1 - f . x0.
      if (track_work) o.work_before = o.contact_forces.cwiseProduct(o.positions).sum();
      double support_work = 0;
      if (o.obstacle_support.size() > 0)
        support_work = -o.obstacle_support.cwiseProduct(o.positions).sum();
      const fem::AdvanceReport rep = naming(o, [&] { return o.sim->advance(o.advanced); });
      o.positions = o.sim->positions();
      if (track_work) o.work_after = o.contact_forces.cwiseProduct(o.positions).sum();
      if (o.obstacle_support.size() > 0)
        support_work += o.obstacle_support.cwiseProduct(o.positions).sum();
      o.cycle_substeps = rep.substeps;
      o.cycle_products = rep.frequency_products;
      o.cycle_min_step = rep.step;
      o.step_cap = std::min(o.sim->options().max_step, o.sim->options().safety_factor * rep.step_limit);
      if (obstacles) {
        lo = lo.cwiseMin(o.positions.colwise().minCoeff().transpose());
        hi = hi.cwiseMax(o.positions.colwise().maxCoeff().transpose());
        resolve_obstacles(o, lo, hi, support_work);
      }
    } else if (o.plan.kinematic) {
      if (o.setup.motion)
        o.pose = o.setup.motion(t_end);
      else
        o.pose.translation += h * o.setup.velocity;
      o.positions = (o.rest * o.pose.rotation.toRotationMatrix().transpose()).rowwise() +
                    o.pose.translation.transpose();
    }
  };

  // 2. Dense meshes follow through the rigid links (only where consumed).
  // 3. Sphere trees follow the coarse nodes (paper 4.4).
  const CollisionSpec& cs = m_settings.collision;
  const auto follow = [&](RuntimeObject& o) {
    if (o.plan.sphere_update && o.lag == 0) {  // (a deferred object moves in the last cycle)
      if (cs.swept) {  // the spheres at the end of the cycle (actual positions)
        update_spheres(o);
        if (cs.layered) collision::enclose_children(o.asset.spheres);
        o.end_spheres = o.asset.spheres.spheres;
      }
      if (m_settings.collision.midpoint && o.sim && m_plan.response) {
        // Midpoint sampling: the forces of this query act during the next
        // cycle, so detect at the positions predicted for its middle.
        o.predicted = o.positions + (0.5 * h) * o.sim->velocities();
        update_deformed_spheres(o, o.predicted);
        if (m_settings.collision.layered) collision::enclose_children(o.asset.spheres);
        // The sweep runs from the start to the prediction, via the end.
        if (cs.swept)
          o.motion = collision::sweep_spheres(o.start_spheres, o.asset.spheres.spheres, o.swept,
                                              o.end_spheres);
      } else if (cs.swept) {
        o.motion = collision::sweep_spheres(o.start_spheres, o.end_spheres, o.swept);
      } else {
        update_spheres(o);
        if (m_settings.collision.layered) collision::enclose_children(o.asset.spheres);
      }
      if (cs.swept) {
        o.speed = o.motion / (o.advanced > 0 ? o.advanced : h);
        std::swap(o.start_spheres, o.end_spheres);  // the next cycle starts at this end
      }
    }
  };
  // Each object's stages in one task: a worker is handed the object once per
  // cycle, not once per stage (each hand-off wakes a parked worker and waits
  // for the slower object). The region's wall time is shared out among the
  // stages in proportion to the objects' own times in each.
  for_each_object([&](int k) {
    RuntimeObject& o = m_objects[static_cast<size_t>(k)];
    const Clock::time_point s0 = Clock::now();
    o.stage_seconds[0] = o.stage_seconds[1] = o.stage_seconds[2] = 0;
    deform(o);
    const Clock::time_point s1 = Clock::now();
    if (last && o.plan.dense_update) update_dense(o);
    const Clock::time_point s2 = Clock::now();
    follow(o);
    o.stage_seconds[0] = std::chrono::duration<double>(s1 - s0).count();
    o.stage_seconds[1] = std::chrono::duration<double>(s2 - s1).count();
    o.stage_seconds[2] = std::chrono::duration<double>(Clock::now() - s2).count();
  });
  // Reduced in object order (the same sums for any thread count).
  for (RuntimeObject& o : m_objects) {
    if (!o.plan.fem) continue;
    if (track_work) {
      m_contact_work -= o.work_before;
      m_contact_work += o.work_after;
    }
    m.substeps += o.cycle_substeps;
    m.frequency_products += o.cycle_products;
    m.min_step = std::min(m.min_step, o.cycle_min_step);
    o.substeps += o.cycle_substeps;
    if (o.cycle_substeps > 0) o.step = o.cycle_min_step;
    m_obstacle_near = m_obstacle_near || o.near_obstacle;
    m.obstacle_depth = std::max(m.obstacle_depth, o.cycle_obstacle_depth);
    if (last) m.obstacle_vertices += o.cycle_obstacle_vertices;
  }
  // Objects that do not move sweep nothing.
  if (cs.swept)
    for (RuntimeObject& o : m_objects)
      if (o.plan.sphere_tree && !o.plan.sphere_update && o.swept.empty())
        collision::still_spheres(o.asset.spheres.spheres, o.swept);
  {
    double part[3] = {0, 0, 0};
    for (const RuntimeObject& o : m_objects)
      for (int q = 0; q < 3; ++q) part[q] += o.stage_seconds[q];
    const double region = seconds_since(t0), sum = part[0] + part[1] + part[2];
    const double links = sum > 0 ? region * part[1] / sum : 0;
    const double spheres = sum > 0 ? region * part[2] / sum : 0;
    m.times.fem += region - links - spheres;
    m.times.links += links;
    m.times.sphere_update += spheres;
  }

  // 4. Interruptible collision queries, one per candidate pair: first the
  //    sweeps and the broad phase decide which pairs need a traversal, then
  //    the budget is shared among those (collision.budget_split).
  t0 = Clock::now();
  if (last) {
    m.pair_list = m.collision_list = 0;
    m.completed_level = std::numeric_limits<int>::max();
    m.active_pairs = 0;
    m.contact_force = 0;
  }
  m_query_pairs.clear();
  for (size_t p = 0; p < m_plan.pairs.size(); ++p) {
    m_pair_budget[p] = 0;
    m_pair_tests[p] = 0;
    // A pair that cannot close this frame (plan_islands) is queried at its
    // end only; its answer (no contact) stands until then.
    if (!last && !m_pair_close[p]) {
      m_swept_hit[p] = 0;
      continue;
    }
    const auto [i, j] = m_plan.pairs[p];
    collision::CollisionResult& r = m_results[p];
    const RuntimeObject& oa = m_objects[i];
    const RuntimeObject& ob = m_objects[j];
    if (cs.swept) {
      // Continuous detection: were the surfaces apart during the whole cycle?
      // (The sweep answers yes or no, stopping at the first touching leaf
      // pair. It shares the query's time budget, running out answers yes; a
      // budget in tests bounds the query's refinement only: the sweep is a
      // safety check, and a test budget small enough to stop it would cycle
      // every frame.)
      collision::SweptRequest sreq;
      sreq.budget_seconds = budget;
      const collision::SweptResult sw = collision::swept_contact(
          oa.asset.spheres, oa.swept, ob.asset.spheres, ob.swept, sreq, m_sweep_stack);
      m.tests += sw.tests;
      const bool hit = sw.touched;
      m_swept_hit[p] = hit;
      if (!hit) {  // apart during the whole cycle: so are the end spheres
        r.colliding.clear();
        r.untested.clear();
        r.front.clear();
        r.interrupted = false;
        r.stop_reason = collision::StopReason::Completed;
        r.tests = 0;
        if (cs.temporal_coherence) m_fronts[p].clear();
        if (cs.on_interrupt == InterruptedResponse::Previous) {
          m_complete[p].colliding.clear();
          m_complete[p].untested.clear();
          m_complete_time[p] = t_end;
        }
        continue;
      }
    }
    if (m_plan.broad_phase && !collision::overlap(oa.asset.spheres.spheres[0],
                                                  ob.asset.spheres.spheres[0])) {
      // Broad phase: root spheres apart, nothing to refine.
      r = collision::CollisionResult{};
      if (cs.swept && start_free && oa.motion + ob.motion > cs.cycle_motion * m_pair_leaf[p]) {
        m_split = true;  // the sweep touched, the end is apart: crossed within the cycle?
        m_split_factor = std::max(
            m_split_factor,
            static_cast<int>(std::ceil((oa.motion + ob.motion) / (cs.cycle_motion * m_pair_leaf[p]))));
      }
      continue;
    }
    m_query_pairs.push_back(p);
  }
  share_budget();
  // The pool of the cycle: the even budget of every pair that needs a query.
  const bool priority = cs.budget_split == BudgetSplit::Priority && m_query_pairs.size() > 1;
  const bool cheapest = cs.budget_split == BudgetSplit::Cheapest && m_query_pairs.size() > 1;
  double pairs_left = static_cast<double>(m_query_pairs.size());
  const double pairs_queried = static_cast<double>(m_query_pairs.size());
  double pool_seconds = budget * pairs_queried, pool_weight = 0;
  double pool_tests = static_cast<double>(cs.query.budget_tests) * pairs_queried;
  for (size_t p : m_query_pairs) pool_weight += m_pair_weight[p];
  for (size_t p : m_query_pairs) {
    const auto [i, j] = m_plan.pairs[p];
    collision::CollisionRequest req = cs.query;
    m_pair_budget[p] = budget;
    m_pair_tests[p] = cs.query.budget_tests;
    if (priority) {  // its weight's fraction of what is left
      const double fraction = m_pair_weight[p] / pool_weight;
      if (std::isfinite(budget))
        m_pair_budget[p] = std::max(pool_seconds * fraction, m_settings.min_query_budget);
      if (cs.query.budget_tests >= 0)
        m_pair_tests[p] = std::max<int64_t>(1, static_cast<int64_t>(std::floor(pool_tests * fraction)));
    }
    if (cheapest) {  // in cost order: complete answers while the pool lasts
      if (std::isfinite(budget))
        m_pair_budget[p] = std::max(cheapest_budget(pool_seconds, pairs_left,
                                                    m_settings.min_query_budget, m_pair_cost_seconds[p]),
                                    m_settings.min_query_budget);
      if (cs.query.budget_tests >= 0)
        m_pair_tests[p] = std::max<int64_t>(
            1, static_cast<int64_t>(std::floor(cheapest_budget(pool_tests, pairs_left, 1, m_pair_cost_tests[p]))));
      pairs_left -= 1;
    }
    req.budget_seconds = m_pair_budget[p];
    if (cs.query.budget_tests >= 0) req.budget_tests = m_pair_tests[p];
    const Clock::time_point q0 = Clock::now();
    req.start_front = nullptr;
    req.record_front = cs.temporal_coherence;
    if (cs.temporal_coherence && !m_fronts[p].empty()) req.start_front = &m_fronts[p];
    collision::CollisionResult& r = m_results[p];
    const RuntimeObject& oa = m_objects[i];
    const RuntimeObject& ob = m_objects[j];
    collision::collide(oa.asset.spheres, ob.asset.spheres, req, r);
    const double query_seconds = seconds_since(q0);
    if (priority || cheapest) {
      pool_seconds -= query_seconds;
      pool_tests -= static_cast<double>(r.tests);
      pool_weight -= m_pair_weight[p];
    }
    // The estimate of the pair's complete cost (Cheapest): its last complete
    // query; an interrupted one needed more than it used (a lower bound,
    // also for a pair never complete: so it is tried with more next time).
    if (!r.interrupted) {
      m_pair_cost_tests[p] = static_cast<double>(r.tests);
      m_pair_cost_seconds[p] = query_seconds;
    } else {
      const auto known = [](double x) { return std::isfinite(x) ? x : 0.0; };
      m_pair_cost_tests[p] = std::max(known(m_pair_cost_tests[p]), static_cast<double>(r.tests) + 1);
      m_pair_cost_seconds[p] = std::max(known(m_pair_cost_seconds[p]), query_seconds);
    }
    if (cs.swept && start_free && r.colliding.empty() && r.untested.empty() &&
        oa.motion + ob.motion > cs.cycle_motion * m_pair_leaf[p]) {
      m_split = true;  // the sweep touched, the end is apart: crossed within the cycle?
      m_split_factor = std::max(
          m_split_factor,
          static_cast<int>(std::ceil((oa.motion + ob.motion) / (cs.cycle_motion * m_pair_leaf[p]))));
    }
    if (cs.temporal_coherence) m_fronts[p] = r.front;
    if (!r.interrupted && cs.on_interrupt == InterruptedResponse::Previous) {
      m_complete[p].colliding = r.colliding;  // copies into reused storage
      m_complete[p].untested = r.untested;
      m_complete_time[p] = t_end;
    }
    if (last) {
      m.pair_list += static_cast<int64_t>(r.untested.size());
      m.collision_list += static_cast<int64_t>(r.colliding.size());
      m.completed_level = std::min(m.completed_level, r.completed_level);
    }
    m.tests += r.tests;
    m.interrupted += r.interrupted ? 1 : 0;
  }
  if (m_plan.pairs.empty()) m.completed_level = 0;
  m.times.collision += seconds_since(t0);

  // 5. Penalty response onto the coarse nodes, applied in the next frame.
  t0 = Clock::now();
  if (m_plan.response) {
    for (RuntimeObject& o : m_objects) o.contact_forces.setZero();
    m_node_stiffness = 0;
    m_contact_rate = 0;
    m_penalty_energy = 0;
    // Each pair's options and the answer it responds to.
    const auto pair_options = [&](size_t p, ContactOptions& co, bool& reuse) {
      const auto [i, j] = m_plan.pairs[p];
      RuntimeObject& a = m_objects[i];
      RuntimeObject& b = m_objects[j];
      co = cs.contact;
      const Eigen::Vector3d ca = a.positions.colwise().mean().transpose();
      const Eigen::Vector3d cb = b.positions.colwise().mean().transpose();
      co.coincident_direction = cb - ca;
      co.mass_a = &a.node_mass;
      co.mass_b = &b.node_mass;
      // Each node a little under half the stable rate, over all the pairs
      // it takes part in (the softening below adds the largest rates of the
      // two sides of a pair; at exactly half, rounding tipped it over and,
      // the scale only falling during an episode, softened every later cycle).
      if (cs.node_rate_cap)
        co.node_rate_limit = 0.45 * (kContactOmegaLimit / h) * (kContactOmegaLimit / h);
      // An interrupted query answers with coarse spheres; with on_interrupt =
      // "previous" the last complete answer (if recent) stands in, evaluated
      // at the current sphere positions; if it is older, the untested pairs
      // respond (the paper) but with at most the penetration that answer had.
      const collision::CollisionResult& r = m_results[p];
      const bool previous = r.interrupted && cs.on_interrupt == InterruptedResponse::Previous &&
                            std::isfinite(m_complete_time[p]);
      // (relative slack: cycle end times are sums of h, the age of a
      // one-frame-old answer can exceed 1 / frame_rate by rounding)
      reuse = previous && t_end - m_complete_time[p] <= cs.previous_max_age * (1 + 1e-9);
      if (previous && !reuse && m_complete_depth[p] > 0)
        co.max_untested_penetration = m_complete_depth[p];
    };
    // Node rates over all pairs: the total each node's cap weighs against
    // (a node touched by two objects must not get the cap from each), and
    // the rates applied, whose sums bound the frequency of all the springs.
    m_total_rate.resize(m_objects.size());
    m_applied_rate.resize(m_objects.size());
    for (size_t k = 0; k < m_objects.size(); ++k) {
      m_total_rate[k].setZero(m_objects[k].rest.rows());
      m_applied_rate[k].setZero(m_objects[k].rest.rows());
    }
    if (cs.node_rate_cap)
      for (size_t p = 0; p < m_plan.pairs.size(); ++p) {
        const auto [i, j] = m_plan.pairs[p];
        ContactOptions co;
        bool reuse = false;
        pair_options(p, co, reuse);
        naming(m_objects[i], m_objects[j], [&] {
          add_contact_rates(m_objects[i].asset.spheres, m_objects[j].asset.spheres,
                            reuse ? m_complete[p] : m_results[p], co, m_total_rate[i], m_total_rate[j]);
        });
      }
    for (size_t p = 0; p < m_plan.pairs.size(); ++p) {
      const auto [i, j] = m_plan.pairs[p];
      RuntimeObject& a = m_objects[i];
      RuntimeObject& b = m_objects[j];
      ContactOptions co;
      bool reuse = false;
      pair_options(p, co, reuse);
      if (cs.node_rate_cap) {
        co.total_rate_a = &m_total_rate[i];
        co.total_rate_b = &m_total_rate[j];
      }
      co.applied_rate_a = &m_applied_rate[i];
      co.applied_rate_b = &m_applied_rate[j];
      const collision::CollisionResult& r = m_results[p];
      if (reuse) ++m.reused;
      const ContactStats st = naming(a, b, [&] {
        return apply_contact_forces(a.asset.spheres, b.asset.spheres, reuse ? m_complete[p] : r, co,
                                    a.contact_forces, b.contact_forces);
      });
      if (!r.interrupted) m_complete_depth[p] = st.max_penetration;
      m_pair_depth[p] = st.max_penetration;
      m_node_stiffness = std::max(m_node_stiffness, st.max_node_stiffness);
      m_penalty_energy += st.penalty_energy;
      m.max_penetration = std::max(m.max_penetration, st.max_penetration);
      m.deep_pairs = std::max(m.deep_pairs, st.deep_pairs);
      m.depth_ratio = std::max(m.depth_ratio, st.max_depth_ratio);
      m.capped_pairs += st.capped_pairs;
      // Deep pairs still approaching stop sinking: an inelastic velocity step
      // on their coarse nodes (deformable objects on both sides only).
      if (cs.deep_step_ratio > 0 && a.sim && b.sim &&
          st.max_depth_ratio > cs.deep_step_ratio) {
        MatX3d va = a.sim->velocities(), vb = b.sim->velocities();
        const DeepContactStats ds = deep_contact_velocity_step(
            a.asset.spheres, b.asset.spheres, reuse ? m_complete[p] : r, a.node_mass, b.node_mass, va,
            vb, cs.deep_step_ratio);
        if (ds.approaching > 0) {
          a.sim->set_velocities(va);
          b.sim->set_velocities(vb);
          m.deep_steps += ds.approaching;
          m.deep_step_energy += ds.removed_energy;
        }
      }
      const double step = cs.cycle_motion * m_pair_leaf[p];
      if (cs.swept && start_free && st.deep_pairs > 0 && a.motion + b.motion > step) {
        // First seen already deeper than a leaf after a motion longer than
        // the cycle should allow: re-run the cycle shorter. (Objects that
        // start overlapping are not split: no shorter cycle would help.)
        m_split = true;
        m_split_factor = std::max(
            m_split_factor, static_cast<int>(std::ceil((a.motion + b.motion) / std::max(step, 1e-300))));
      }
      if (last) {
        m.active_pairs += st.active_pairs;
        m.contact_force += st.total_force_a.norm();
      }
    }
    // The largest frequency of all the springs together: at most the largest
    // over responding pairs of the two sides' largest node rates, each summed
    // over every pair the node takes part in (Gershgorin on B^T M^-1 B W,
    // B the pairs' node share vectors: row p sums to at most the rates of
    // p's nodes weighted by shares that add up to 1 per side). For one
    // object pair: ContactStats::max_rate.
    for (size_t p = 0; p < m_plan.pairs.size(); ++p)
      if (m_pair_depth[p] > 0) {
        const auto [i, j] = m_plan.pairs[p];
        m_contact_rate = std::max(m_contact_rate, m_applied_rate[i].maxCoeff() + m_applied_rate[j].maxCoeff());
      }
  }
  // Past the staggered scheme's stability margin (explicit limit: omega h = 2)
  // soften the response rather than let it pump energy. The scale only
  // decreases during a contact (reset once every pair is apart): a penalty
  // that is softer while loading than while unloading would gain energy.
  if (m_plan.response) {
    if (m_node_stiffness == 0 && contact_free()) m_contact_scale = 1;
    if (m_node_stiffness > 0) {
      // Per node: its own stiffness over its own mass (the rates summed
      // over the pairs, see above).
      // Not the largest stiffness over the lightest mass of all objects:
      // those are on different nodes, and on the 600-tet meshes of
      // many_objects (lightest node 7.4e-6 kg) that bound was 4x the
      // rate and, as the scale only decreases during an episode, softened
      // the penalty to 0.4% within 5 frames of contact: the objects sank
      // through each other (max penetration 2.8 m by frame 27).
      const double omega_h = std::sqrt(m_contact_rate) * h;
      if (omega_h > kContactOmegaLimit)
        m_contact_scale = std::min(m_contact_scale,
                                   (kContactOmegaLimit / omega_h) * (kContactOmegaLimit / omega_h));
    }
    if (m_contact_scale < 1 && m_node_stiffness > 0) {
      for (RuntimeObject& o : m_objects) o.contact_forces *= m_contact_scale;
      m_penalty_energy *= m_contact_scale;
      ++m.softened;
    }
    if (m_settings.collision.passive) limit_contact_work(h, m);
  }
  m.times.response += seconds_since(t0);
  if (last) m.penalty_energy = m_penalty_energy;
  if (m_cycle_observer) m_cycle_observer(*this);
}

void World::limit_contact_work(double h, FrameMetrics& m) {
  if (m_node_stiffness == 0) {
    if (contact_free()) {  // the episode is over
      m_contact_work = 0;
      m_passive_allowance = -1;
    }
    return;
  }
  double power = 0, kinetic = 0;  // contact force . velocity (W); kinetic energy (J)
  for (const RuntimeObject& o : m_objects) {
    if (!o.sim) continue;  // static and kinematic objects: external motion
    const MatX3d& v = o.sim->velocities();
    power += o.contact_forces.cwiseProduct(v).sum();
    if (m_passive_allowance < 0) kinetic += o.sim->model().kinetic_energy(v);
  }
  if (m_passive_allowance < 0) m_passive_allowance = kPassiveTolerance * kinetic;
  // The contact is passive while the net work its forces have done on the
  // objects (negative while it resists their approach, positive while it
  // pushes them apart) stays below the allowance: it may give back what it
  // absorbed, not more. The work of the coming cycle is predicted from the
  // current velocities; the actual work is summed in cycle().
  const double work = h * power;
  const double room = m_passive_allowance - m_contact_work;
  if (work <= 0 || work <= room) return;
  const double s = std::clamp(room / work, 0.0, 1.0);
  for (RuntimeObject& o : m_objects) o.contact_forces *= s;
  m_penalty_energy *= s;
  ++m.limited;
}

void World::obstacle_layer(RuntimeObject& o, double threshold, bool same_triples) const {
  const int num_links = o.asset.links.num_links();
  if (o.obstacle_dense.rows() != num_links) o.obstacle_dense.resize(num_links, 3);
  if (same_triples && m_settings.obstacle_cull) {  // the same layer at the current positions
    o.links.apply_links(o.positions, o.obstacle_triples, o.obstacle_layer, o.obstacle_dense);
    return;
  }
  o.obstacle_layer.clear();
  if (!m_settings.obstacle_cull) {  // the reference: every vertex
    o.links.apply(o.positions, o.obstacle_dense);
    for (int v = 0; v < num_links; ++v) o.obstacle_layer.push_back(v);
    return;
  }
  // Each near obstacle's linear coordinates of the nodes: a box's local
  // coordinates (its signed distance is at least max_k |q_k| - h_k), a
  // plane's signed distance. Linear, so a vertex's value lies within its
  // link's |c| of the range of its triple's nodes' values (its origin is a
  // convex combination of them, the frame orthonormal).
  const int n = static_cast<int>(o.positions.rows());
  o.obstacle_local.resize(m_settings.obstacles.size());
  const double scale = o.positions.cwiseAbs().maxCoeff() + o.max_link;
  std::vector<double> slack(m_settings.obstacles.size(), 0.0);
  for (int b : o.obstacle_near) {
    const Obstacle& ob = m_settings.obstacles[static_cast<size_t>(b)];
    MatX3d& q = o.obstacle_local[static_cast<size_t>(b)];
    if (ob.type == Obstacle::Type::Plane) {
      q.resize(n, 3);
      q.col(0) = (o.positions.rowwise() - ob.point.transpose()) * ob.normal;
    } else {
      q = (o.positions.rowwise() - ob.point.transpose()) * ob.axes;
    }
    // Rounding of the links, of the signed distance and of origin weights
    // that sum to 1 within 1e-9 (validate(RigidLinks)): far below it.
    slack[static_cast<size_t>(b)] =
        1e-8 * (1 + scale + ob.point.cwiseAbs().maxCoeff() +
                (ob.type == Obstacle::Type::Box ? ob.half_extents.maxCoeff() : 0.0));
  }
  o.obstacle_triples.clear();
  // Per triple, per near obstacle: its nodes' coordinates (node-major, 3 x 3;
  // a plane: the first of each three), loaded once for the triple's bound
  // and then for each of its links'.
  const size_t num_near = o.obstacle_near.size();
  std::vector<double>& nq = o.obstacle_scratch;
  nq.resize(9 * num_near);
  const std::vector<int32_t>& links = o.links.triple_links();
  // Whether triple t may hold a vertex closer than thr to a near obstacle
  // (a lower bound of their signed distance, per obstacle: from the range
  // of its nodes' coordinates on each axis, less triple_reach); loads nq.
  const auto near_triple = [&](int t, double thr) {
    const double reach = o.triple_reach[static_cast<size_t>(t)];
    const int32_t* nodes = o.links.triple_nodes(t);
    bool take = false;
    for (size_t i = 0; i < num_near; ++i) {
      const int b = o.obstacle_near[i];
      const Obstacle& ob = m_settings.obstacles[static_cast<size_t>(b)];
      const MatX3d& q = o.obstacle_local[static_cast<size_t>(b)];
      double* v = &nq[9 * i];
      const bool plane = ob.type == Obstacle::Type::Plane;
      for (int a = 0; a < 3; ++a)
        for (int d = 0; d < (plane ? 1 : 3); ++d) v[3 * a + d] = q(nodes[a], d);
      if (take) continue;  // (the loads are still needed for the links)
      double bound;
      if (plane) {
        bound = std::min({v[0], v[3], v[6]});
      } else {
        bound = -std::numeric_limits<double>::infinity();
        for (int k = 0; k < 3; ++k) {
          const double lo = std::min({v[k], v[3 + k], v[6 + k]});
          const double hi = std::max({v[k], v[3 + k], v[6 + k]});
          bound = std::max(bound, std::max(lo, -hi) - ob.half_extents[k]);
        }
      }
      // (NaN: taken)
      take = !(bound - reach - slack[static_cast<size_t>(b)] >= thr);
    }
    return take;
  };
  // The candidates: the triples within kObstacleListMargin more than the
  // threshold when the list was made, kept while no node has moved that far
  // since (a node moving by D changes a bound by at most D: the obstacle
  // frames are orthonormal) and the near obstacles are the same.
  const int num_triples = o.links.num_triples();
  const double list_slack = 1e-9 * (1 + scale);
  const bool reuse =
      o.obstacle_list_near == o.obstacle_near && threshold <= o.obstacle_list_threshold &&
      o.obstacle_list_from.rows() == n &&
      (o.positions - o.obstacle_list_from).rowwise().squaredNorm().maxCoeff() <=
          std::pow(std::max(0.0, kObstacleListMargin - list_slack), 2);
  if (!reuse) {  // (made for the projection's threshold too, so that both callers use it)
    const double list_threshold = std::max(threshold, kObstacleStep);
    o.obstacle_list.clear();
    for (int t = 0; t < num_triples; ++t)
      if (o.triple_reach[static_cast<size_t>(t)] < 0 ||
          near_triple(t, list_threshold + kObstacleListMargin))
        o.obstacle_list.push_back(t);
    o.obstacle_list_near = o.obstacle_near;
    o.obstacle_list_threshold = list_threshold;
    o.obstacle_list_from = o.positions;
  }
  for (int32_t t : o.obstacle_list) {
    const double reach = o.triple_reach[static_cast<size_t>(t)];
    const int32_t begin = o.links.links_of_triple(t), end = o.links.links_of_triple(t + 1);
    if (reach < 0) {  // no bound: every link
      o.obstacle_triples.push_back(t);
      o.obstacle_layer.insert(o.obstacle_layer.end(), links.begin() + begin, links.begin() + end);
      continue;
    }
    const bool take = near_triple(t, threshold);
    if (!take) continue;
    o.obstacle_triples.push_back(t);
    // Per link: the same bound from its own origin (sum_i alpha_i q_i, exact
    // for any weights: q is linear) and its own link length (its vector c
    // moves the vertex by at most |c| along any axis of the obstacle's
    // frame, the link frame being orthonormal).
    for (int32_t j = begin; j < end; ++j) {
      const double* w = &o.link_bound[4 * static_cast<size_t>(j)];
      const double c = w[3];
      bool near = false;
      for (size_t i = 0; i < num_near && !near; ++i) {
        const int b = o.obstacle_near[i];
        const Obstacle& ob = m_settings.obstacles[static_cast<size_t>(b)];
        const double* v = &nq[9 * i];
        double bound;
        if (ob.type == Obstacle::Type::Plane) {
          bound = w[0] * v[0] + w[1] * v[3] + w[2] * v[6];
        } else {
          bound = -std::numeric_limits<double>::infinity();
          for (int d = 0; d < 3; ++d)
            bound = std::max(bound, std::abs(w[0] * v[d] + w[1] * v[3 + d] + w[2] * v[6 + d]) -
                                        ob.half_extents[d]);
        }
        near = !(bound - c - slack[static_cast<size_t>(b)] >= threshold);  // (NaN: taken)
      }
      if (near) o.obstacle_layer.push_back(links[static_cast<size_t>(j)]);
    }
  }
  o.links.apply_links(o.positions, o.obstacle_triples, o.obstacle_layer, o.obstacle_dense);
  // (in triple order: the callers break ties by vertex index, as a pass over
  // every vertex in order would)
}

void World::resolve_obstacles(RuntimeObject& o, const Eigen::Vector3d& lo_in,
                              const Eigen::Vector3d& hi_in, double support_work) const {
  // Within reach? The dense surface lies within max_link of the coarse
  // nodes' convex hull (a link origin is a convex combination of three
  // nodes; the link keeps its length), which lies in [lo, hi]. Only the
  // obstacles within reach are tested.
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(o.max_link);
  const Eigen::Vector3d lo = lo_in - pad, hi = hi_in + pad;
  o.obstacle_near.clear();
  o.obstacle_rate = 0;
  for (size_t b = 0; b < m_settings.obstacles.size(); ++b)
    if (m_settings.obstacles[b].lower_bound(lo, hi) <= 0) o.obstacle_near.push_back(static_cast<int>(b));
  if (o.obstacle_near.empty()) return;
  o.near_obstacle = true;
  // The energy before the projection: the state as it is until the first
  // move (only needed when something moves).
  double e_before = 0;
  const int n = static_cast<int>(o.positions.rows());
  MatX3d corr(n, 3), dir = MatX3d::Zero(n, 3);
  const auto& nodes = o.asset.links.nodes;
  // Fixed nodes stay where they are (a vertex held only by fixed nodes stays
  // inside; obstacle_depth reports it).
  std::vector<char> fixed(static_cast<size_t>(n), 0);
  for (int j : o.setup.fixed_nodes) fixed[static_cast<size_t>(j)] = 1;
  // A few passes: a vertex whose three nodes moved by different amounts
  // moves by their weighted mean plus a small rotation of its link.
  constexpr int kPasses = 6;
  constexpr double kTolerance = 1e-6;  // m
  // The layer is found once, kObstacleStep wider than needed, and kept while
  // the passes have moved no node farther than that (a node moving by D
  // changes the layer's bound by at most D).
  constexpr double kMargin = kObstacleStep;
  double shifted = 0;  // largest total correction of a node since the layer was found, bound
  std::vector<int32_t> setter(static_cast<size_t>(n));  // the vertex that set corr.row(j)
  bool moved = false;
  for (int pass = 0; pass < kPasses; ++pass) {
    const bool keep = pass > 0 && shifted <= kMargin;
    obstacle_layer(o, -kTolerance + kMargin, keep);
    if (!keep) shifted = 0;
    corr.setZero();
    bool inside = false;
    for (int32_t v : o.obstacle_layer) {
      const Eigen::Vector3d p = o.obstacle_dense.row(v).transpose();
      for (int b : o.obstacle_near) {
        const Obstacle& ob = m_settings.obstacles[static_cast<size_t>(b)];
        Eigen::Vector3d nrm;
        const double d = ob.signed_distance(p, &nrm);
        if (!(d < -kTolerance)) continue;
        inside = true;
        if (pass == 0) {
          o.cycle_obstacle_depth = std::max(o.cycle_obstacle_depth, -d);
          ++o.cycle_obstacle_vertices;
        }
        // Per node the largest correction; between equal ones, that of the
        // lowest vertex (the layer comes in triple order).
        const Eigen::Vector3d need = -d * nrm;
        const double need2 = need.squaredNorm();
        for (int k = 0; k < 3; ++k) {
          const int j = nodes(v, k);
          if (fixed[static_cast<size_t>(j)]) continue;
          const double have2 = corr.row(j).squaredNorm();
          if (need2 > have2 || (need2 == have2 && have2 > 0 && v < setter[static_cast<size_t>(j)])) {
            corr.row(j) = need.transpose();
            setter[static_cast<size_t>(j)] = v;
          }
        }
      }
    }
    if (pass == 0 && o.advanced > 0) o.obstacle_rate = o.cycle_obstacle_depth / o.advanced;
    if (!inside) break;
    if (!moved) e_before = mechanical_energy(*o.sim, m_settings.gravity);
    double largest = 0;
    for (int j = 0; j < n; ++j)
      if (corr.row(j).squaredNorm() > 0) {
        o.positions.row(j) += corr.row(j);
        dir.row(j) = corr.row(j).normalized();
        largest = std::max(largest, corr.row(j).norm());
      }
    shifted += largest * (1 + 1e-12);
    moved = true;
  }
  MatX3d vel = o.sim->velocities();
  if (moved) {
    // Inelastic: the moved nodes lose their velocity into the obstacle.
    for (int j = 0; j < n; ++j) {
      const double vn = vel.row(j).dot(dir.row(j));
      if (vn < 0) vel.row(j) -= vn * dir.row(j);
    }
    o.sim->correct_positions(o.positions);  // (keeps the step estimate: strain-checked)
    o.sim->set_velocities(vel);
  }
  // Never a source of energy. Moving nodes out stores elastic energy (only
  // some nodes move) and lifts the object against gravity, and a support
  // held constant over the cycle does work on a node that lifts off. What
  // they added beyond what the removed velocity took away is taken from the
  // kinetic energy (every velocity scaled alike); what it cannot pay now is
  // paid by the next cycles.
  const double change = moved ? mechanical_energy(*o.sim, m_settings.gravity) - e_before : 0.0;
  const double excess = change + support_work + o.obstacle_debt;
  if (!(excess > 0)) {
    o.obstacle_debt = 0;
    return;
  }
  const double kinetic = o.sim->model().kinetic_energy(vel);
  const double paid = std::min(excess, kinetic);
  if (paid > 0) o.sim->set_velocities(vel * std::sqrt(std::max(0.0, (kinetic - paid) / kinetic)));
  o.obstacle_debt = excess - paid;
}

bool World::obstacle_support(RuntimeObject& o) const {
  // Only the obstacles a vertex may be within kObstacleContact of (see
  // resolve_obstacles; 1 um more against rounding).
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(o.max_link + kObstacleContact + 1e-6);
  const Eigen::Vector3d lo = o.positions.colwise().minCoeff().transpose() - pad;
  const Eigen::Vector3d hi = o.positions.colwise().maxCoeff().transpose() + pad;
  o.obstacle_near.clear();
  for (size_t b = 0; b < m_settings.obstacles.size(); ++b)
    if (!(m_settings.obstacles[b].lower_bound(lo, hi) > 0)) o.obstacle_near.push_back(static_cast<int>(b));
  if (o.obstacle_near.empty()) return false;
  obstacle_layer(o, kObstacleContact);
  const int n = static_cast<int>(o.positions.rows());
  MatX3d normal = MatX3d::Zero(n, 3);
  // Per node the normal of its highest vertex touching (the layer comes in
  // triple order; a pass over every vertex in order keeps the last).
  std::vector<int32_t> writer(static_cast<size_t>(n), -1);
  const auto& nodes = o.asset.links.nodes;
  bool any = false;
  for (int32_t v : o.obstacle_layer) {
    const Eigen::Vector3d p = o.obstacle_dense.row(v).transpose();
    for (int b : o.obstacle_near) {
      const Obstacle& ob = m_settings.obstacles[static_cast<size_t>(b)];
      Eigen::Vector3d nrm;
      if (!(ob.signed_distance(p, &nrm) < kObstacleContact)) continue;
      any = true;
      for (int k = 0; k < 3; ++k) {
        const int j = nodes(v, k);
        if (v < writer[static_cast<size_t>(j)]) continue;
        normal.row(j) = nrm.transpose();
        writer[static_cast<size_t>(j)] = v;
      }
    }
  }
  if (!any) return false;
  MatX3d f(n, 3);
  o.sim->model().total_force(o.positions, o.sim->velocities(), f);
  o.obstacle_support = MatX3d::Zero(n, 3);
  for (int j = 0; j < n; ++j) {
    const double fn = f.row(j).dot(normal.row(j));
    if (fn < 0) o.obstacle_support.row(j) = -fn * normal.row(j);
  }
  return true;
}

bool World::contact_free() const {
  if (m_obstacle_near) return false;
  for (const collision::CollisionResult& r : m_results)
    if (!r.colliding.empty() || !r.untested.empty()) return false;
  return true;
}

bool World::contact_ahead(double dt) {
  const CollisionSpec& cs = m_settings.collision;
  if (!cs.swept || !cs.predict_contact || m_plan.pairs.empty()) return false;
  // The stretch the trial's sweep covers: the frame, then half a frame to
  // the midpoint prediction of the next cycle.
  const double ahead = cs.midpoint && m_plan.response ? 1.5 * dt : dt;
  const size_t n = m_objects.size();
  m_ahead_saved.resize(n);
  m_ahead_swept.resize(n);
  m_ahead_motion.assign(n, 0.0);
  m_ahead_done.assign(n, 0);
  // Deformable objects move with their node velocities; static ones stay.
  const auto predictable = [](const RuntimeObject& o) {
    return o.plan.sphere_tree && (o.sim ? o.plan.sphere_update : !o.plan.kinematic);
  };
  const auto predict = [&](size_t k) {
    if (m_ahead_done[k]) return;
    m_ahead_done[k] = 1;
    RuntimeObject& o = m_objects[k];
    std::vector<collision::SweptSphere>& sw = m_ahead_swept[k];
    if (!o.sim) {
      collision::still_spheres(o.asset.spheres.spheres, sw);
      return;
    }
    m_ahead_saved[k] = o.asset.spheres.spheres;
    const MatX3d x = o.positions + ahead * o.sim->velocities();
    update_deformed_spheres(o, x);
    if (cs.layered) collision::enclose_children(o.asset.spheres);
    // (no margin: a sweep grown by a fraction of a leaf touched at its start
    // in the frame after the main job's contact, the objects just apart)
    m_ahead_motion[k] = collision::sweep_spheres(o.start_spheres, o.asset.spheres.spheres, sw);
    std::swap(m_ahead_saved[k], o.asset.spheres.spheres);  // the spheres as they were
  };
  bool touched = false;
  for (size_t p = 0; p < m_plan.pairs.size() && !touched; ++p) {
    const auto [i, j] = m_plan.pairs[p];
    RuntimeObject& a = m_objects[i];
    RuntimeObject& b = m_objects[j];
    if (!predictable(a) || !predictable(b)) continue;
    // (the sweep starts at the spheres of the current positions, and the
    // cycles are sized by the objects' sub-steps, known once they have
    // advanced: in a World's first frame the trial measures them)
    const auto ready = [](const RuntimeObject& o) {
      return !o.sim || (o.start_spheres.size() == o.asset.spheres.spheres.size() && o.step_cap > 0);
    };
    if (!ready(a) || !ready(b)) continue;
    // Root spheres farther apart than the nodes can move (at their present
    // speeds) plus the margins: nothing to sweep.
    const auto reach_of = [&](const RuntimeObject& o) {
      // (a leaf radius more: the spheres may grow as the object deforms)
      return o.sim ? ahead * o.sim->velocities().rowwise().norm().maxCoeff() + o.leaf_radius : 0.0;
    };
    const collision::Sphere& ra = a.asset.spheres.spheres[0];
    const collision::Sphere& rb = b.asset.spheres.spheres[0];
    const double gap = (ra.center() - rb.center()).norm() - ra.r - rb.r;
    if (gap > reach_of(a) + reach_of(b)) continue;  // (NaN: swept)
    predict(i);
    predict(j);
    collision::SweptRequest req;
    touched = collision::swept_contact(a.asset.spheres, m_ahead_swept[i], b.asset.spheres,
                                       m_ahead_swept[j], req, m_sweep_stack)
                  .touched;
  }
  if (touched)
    for (size_t k = 0; k < n; ++k)
      if (m_ahead_done[k] && m_objects[k].sim) m_objects[k].speed = m_ahead_motion[k] / dt;
  return touched;
}

void World::save(Snapshot& s) const {
  s.positions.resize(m_objects.size());
  s.velocities.resize(m_objects.size());
  s.poses.resize(m_objects.size());
  for (size_t i = 0; i < m_objects.size(); ++i) {
    const RuntimeObject& o = m_objects[i];
    s.positions[i] = o.positions;
    s.poses[i] = o.pose;
    if (o.sim) s.velocities[i] = o.sim->velocities();
  }
  s.fronts = m_fronts;
  s.complete = m_complete;
  s.complete_time = m_complete_time;
  s.complete_depth = m_complete_depth;
  s.node_stiffness = m_node_stiffness;
  s.contact_scale = m_contact_scale;
  s.contact_work = m_contact_work;
  s.passive_allowance = m_passive_allowance;
  s.start_spheres.resize(m_objects.size());
  s.obstacle_debt.resize(m_objects.size());
  s.obstacle_support.resize(m_objects.size());
  s.near_obstacle.resize(m_objects.size());
  s.lags.resize(m_objects.size());
  for (size_t i = 0; i < m_objects.size(); ++i) {
    s.start_spheres[i] = m_objects[i].start_spheres;
    s.obstacle_debt[i] = m_objects[i].obstacle_debt;
    s.obstacle_support[i] = m_objects[i].obstacle_support;
    s.near_obstacle[i] = m_objects[i].near_obstacle;
    s.lags[i] = m_objects[i].lag;
  }
}

void World::restore(const Snapshot& s) {
  for (size_t i = 0; i < m_objects.size(); ++i) {
    RuntimeObject& o = m_objects[i];
    o.positions = s.positions[i];
    o.pose = s.poses[i];
    o.contact_forces.setZero();  // the trial started contact-free: no forces
    if (o.sim) {
      o.sim->set_positions(s.positions[i]);
      o.sim->set_velocities(s.velocities[i]);
    }
  }
  m_fronts = s.fronts;
  m_complete = s.complete;
  m_complete_time = s.complete_time;
  m_complete_depth = s.complete_depth;
  m_node_stiffness = s.node_stiffness;
  m_contact_scale = s.contact_scale;
  m_contact_work = s.contact_work;
  m_passive_allowance = s.passive_allowance;
  m_penalty_energy = 0;  // the trial started contact-free
  for (size_t i = 0; i < m_objects.size(); ++i) {
    m_objects[i].start_spheres = s.start_spheres[i];
    m_objects[i].obstacle_debt = s.obstacle_debt[i];
    m_objects[i].obstacle_support = s.obstacle_support[i];
    m_objects[i].near_obstacle = s.near_obstacle[i];
    m_objects[i].lag = s.lags[i];
  }
  // The rolled-back interval started contact-free: so do its queries.
  for (collision::CollisionResult& r : m_results) {
    r.colliding.clear();
    r.untested.clear();
  }
}

FrameMetrics World::step() { return advance(std::nullopt); }

FrameMetrics World::step(double budget_seconds) {
  if (!(budget_seconds > 0))
    throw ParameterError("World::step: budget_seconds must be > 0 (infinity for none)");
  return advance(budget_seconds);
}

FrameMetrics World::advance(std::optional<double> budget) {
  const Clock::time_point frame_start = Clock::now();
  const double dt = 1.0 / m_settings.frame_rate;
  FrameMetrics m;
  m.frame = m_frame;
  m.min_step = std::numeric_limits<double>::infinity();
  m.budget = budget ? *budget : m_settings.collision.query.budget_seconds;
  for (RuntimeObject& o : m_objects) o.substeps = 0;

  // Real-time mode: collision detection gets what is left of the frame (of
  // the first `fraction` of it), shared between the pairs, but never less
  // than min_query_budget per query. FEM is never cut.
  const bool realtime = !budget && m_settings.target_fps > 0;
  if (realtime) m.deadline = 1.0 / m_settings.target_fps;
  int floored = 0;  // queries given the minimum budget (the rolled-back trial's included)
  const auto budget_at = [&](double fraction) {
    if (!realtime || m_plan.pairs.empty()) return m.budget;
    const double left = fraction / m_settings.target_fps - seconds_since(frame_start);
    const double share = left / static_cast<double>(m_plan.pairs.size());
    if (share < m_settings.min_query_budget) {
      floored += static_cast<int>(m_plan.pairs.size());
      return m_settings.min_query_budget;
    }
    return share;
  };

  // The contact response is explicit and staggered: forces computed from one
  // query act until the next. Its stiffness k on a node of mass m oscillates
  // at omega = sqrt(k / m), stable only if the query interval h obeys
  // omega h <= kContactOmegaStep (under the explicit limit 2). So a frame runs as
  // many detection/response cycles as that needs; FEM sub-steps inside each.
  // With collision.swept, also as many as keep each pair's relative motion
  // per cycle under collision.cycle_motion leaf radii (motion_cycles()).
  // Only the pairs that may touch within the frame (and their objects) run
  // the cycles; the others advance over the frame at once (plan_islands).
  for (RuntimeObject& o : m_objects) o.deferred = false;
  std::fill(m_pair_close.begin(), m_pair_close.end(), 1);
  m_close_min_mass = m_min_node_mass;
  const auto stiff_cycles = [&] {
    bool any_close = false;
    for (char c : m_pair_close) any_close = any_close || c;
    return any_close ? contact_cycles(dt) : 1;
  };
  int cycles = contact_cycles(dt);
  const auto bounds = [&] {
    m.cycles_penalty = stiff_cycles();
    m.cycles_motion = motion_cycles(dt);
    return std::max({m.cycles_penalty, m.cycles_motion, 1});
  };
  if (!contact_free()) {
    plan_islands(dt);
    cycles = bounds();
  }
  m.cycles = 0;

  // While the objects are apart, no force acts and one cycle per frame gives
  // the same motion. So a frame that starts contact-free is first tried as a
  // single cycle; if its closing query finds a contact (with collision.swept:
  // if the sweep of the frame touches anywhere), the frame is rolled back and
  // re-run in full cycles, so contact forces start from the cycle in which the
  // contact begins, as if every frame had been cycled. (Without the sweep, a
  // contact that begins and ends inside one trial frame is missed.)
  const bool swept = m_settings.collision.swept;
  const bool apart = (cycles > 1 || swept) && m_settings.collision.single_cycle_when_apart && contact_free();
  if (apart && contact_ahead(dt)) {
    // A trial would find the contact and be rolled back: cycles at once.
    m.predicted = 1;
    plan_islands(dt);
    cycles = bounds();
  } else if (apart) {
    save(m_snapshot);
    FrameMetrics trial = m;
    trial.cycles = 1;
    trial.budget = budget_at(1.0);
    m_split = false;
    cycle(dt, m_time + dt, trial.budget, true, true, trial);
    bool touched = !contact_free();
    if (swept)
      for (char hit : m_swept_hit) touched = touched || hit;
    if (!touched) {
      m = trial;
      m.min_budget_queries = floored;
      return finish_frame(m, frame_start);
    }
    restore(m_snapshot);
    m.rollback = 1;
    m.times = trial.times;  // the rolled-back work is part of the frame's cost
    m.tests = trial.tests;
    m.substeps = trial.substeps;  // (as the objects' own counts, RuntimeObject::substeps)
    m.frequency_products = trial.frequency_products;
    // The trial measured each object's motion over the frame.
    plan_islands(dt);
    cycles = bounds();
  }
  run_cycles(m_time, dt, aligned_cycles(dt, cycles), 0, true, budget_at, m);
  m.min_budget_queries = floored;
  return finish_frame(m, frame_start);
}

void World::run_cycles(double t0, double length, int n, int depth, bool ends_frame,
                       const std::function<double(double)>& budget_at, FrameMetrics& m) {
  const double dt = 1.0 / m_settings.frame_rate;
  const double h = length / n;
  if (m_split_snapshots.size() <= static_cast<size_t>(depth)) m_split_snapshots.resize(depth + 1);
  for (int c = 0; c < n; ++c) {
    const bool last = ends_frame && c + 1 == n;
    const double t_end = c + 1 == n ? t0 + length : t0 + (c + 1) * h;
    const bool start_free = contact_free();
    const bool can_split = m_settings.collision.swept && start_free && depth < kMaxSplitDepth;
    FrameMetrics before;
    if (can_split) {
      save(m_split_snapshots[depth]);
      before = m;
    }
    m_split = false;
    m_split_factor = 2;
    m.budget = budget_at((t_end - m_time) / dt);
    cycle(h, t_end, m.budget, last, start_free, m);
    ++m.cycles;
    if (can_split && m_split) {
      // Rolled back: the work done stays counted, its contact results do not.
      restore(m_split_snapshots[depth]);
      const StageTimes times = m.times;
      const int64_t tests = m.tests;
      const int cycles = m.cycles, substeps = m.substeps;
      const double min_step = m.min_step;
      m = before;
      m.times = times;
      m.tests = tests;
      m.cycles = cycles;
      m.substeps = substeps;
      m.min_step = min_step;
      ++m.subdivided;
      run_cycles(t_end - h, h, std::clamp(m_split_factor, 2, kMaxSplit), depth + 1, last, budget_at,
                 m);
    }
  }
}

FrameMetrics World::finish_frame(FrameMetrics& m, Clock::time_point frame_start) {
  m.energy = m_penalty_energy;
  // (an element pass per object: on the workers, summed in object order)
  m_object_energy.assign(m_objects.size(), 0.0);
  for_each_object([&](int k) {
    RuntimeObject& o = m_objects[static_cast<size_t>(k)];
    if (o.sim) m_object_energy[static_cast<size_t>(k)] = mechanical_energy(*o.sim, m_settings.gravity);
  });
  for (double e : m_object_energy) m.energy += e;
  // Exact reference: intersecting dense triangles (for accuracy studies).
  if (m_plan.exact_reference) {
    m.exact_contacts = 0;
    for (const auto& [i, j] : m_plan.pairs) {
      const RuntimeObject& a = m_objects[i];
      const RuntimeObject& b = m_objects[j];
      const collision::AabbTree ta(a.dense, a.asset.dense.F);
      const collision::AabbTree tb(b.dense, b.asset.dense.F);
      m.exact_contacts +=
          static_cast<int>(collision::intersecting_triangle_pairs(ta, a.dense, a.asset.dense.F, tb,
                                                                  b.dense, b.asset.dense.F)
                               .size());
    }
  }

  if (!std::isfinite(m.min_step)) m.min_step = 0;
  ++m_frame;
  m_time += 1.0 / m_settings.frame_rate;
  m.time = m_time;
  m.wall = seconds_since(frame_start);
  if (m.deadline > 0) {
    m.deadline_met = m.wall <= m.deadline ? 1 : 0;
    m.lateness = std::max(0.0, m.wall - m.deadline);
    const double own = m.times.fem + m.times.links + m.times.sphere_update;
    m.fem_over_deadline = own > m.deadline ? 1 : 0;
    if (m.fem_over_deadline && !m_deadline_warned) {
      m_deadline_warned = true;
      std::ostringstream os;
      os.precision(3);
      os << "real-time mode: the deadline of " << 1e3 * m.deadline << " ms per frame (target_fps "
         << m_settings.target_fps << ") cannot be met: FEM, links and sphere update alone took "
         << 1e3 * own << " ms in frame " << m.frame << " (FEM " << 1e3 * m.times.fem << " ms, "
         << m.substeps << " sub-steps over " << m_threads
         << " thread(s)); FEM is never skipped, so frames run late and collision runs at its "
            "minimum budget of "
         << 1e3 * m_settings.min_query_budget << " ms per query";
      m.deadline_warning = os.str();
    }
  }
  return m;
}

}  // namespace icd::coupling
