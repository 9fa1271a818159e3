#include "experiments/runner/scene.hpp"
#include "experiments/runner/locations.hpp"

#include <cmath>
#include <limits>
#include <set>

#include <icd/config.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/input_file.hpp>

namespace icd::runner {
namespace {

// Reads the fields of one JSON object, remembering the field path for
// messages, and rejects fields nobody asked for.
class Fields {
 public:
  Fields(const Json& j, std::string path, const std::string& source)
      : m_path(std::move(path)), m_source(source) {
    if (!j.is_object()) fail(m_path, std::string("must be an object, got ") + j.type_name());
    m_obj = &j.as_object();
  }

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError(m_source + ": " + (field.empty() ? "<root>" : field) + ": " + what);
  }
  std::string path(const std::string& key) const {
    return m_path.empty() ? key : m_path + "." + key;
  }

  const Json* get(const std::string& key) {
    m_used.insert(key);
    auto it = m_obj->find(key);
    return it == m_obj->end() ? nullptr : &it->second;
  }

  double number(const std::string& key, double def, double lo, double hi, bool lo_open = false) {
    const Json* j = get(key);
    if (!j) return def;
    if (!j->is_number()) fail(path(key), std::string("must be a number, got ") + j->type_name());
    const double v = j->as_number();
    if (!std::isfinite(v))
      fail(path(key), "must be a finite number, got one beyond the double range (about 1.8e308)");
    if (v < lo || v > hi || (lo_open && v == lo))
      fail(path(key), "must be in " + std::string(lo_open ? "(" : "[") + fmt(lo) + ", " + fmt(hi) +
                          "], got " + fmt(v));
    return v;
  }
  int integer(const std::string& key, int def, int lo, int hi) {
    const double v = number(key, def, lo, hi);
    if (v != std::floor(v)) fail(path(key), "must be an integer, got " + fmt(v));
    return static_cast<int>(v);
  }
  bool boolean(const std::string& key, bool def) {
    const Json* j = get(key);
    if (!j) return def;
    if (!j->is_bool()) fail(path(key), std::string("must be true or false, got ") + j->type_name());
    return j->as_bool();
  }
  std::string string(const std::string& key, const std::string& def,
                     const std::vector<std::string>& allowed = {}) {
    const Json* j = get(key);
    if (!j) return def;
    if (!j->is_string()) fail(path(key), std::string("must be a string, got ") + j->type_name());
    const std::string& s = j->as_string();
    if (!allowed.empty()) {
      bool ok = false;
      std::string list;
      for (const auto& a : allowed) {
        ok |= a == s;
        list += (list.empty() ? "" : ", ") + ('"' + a + '"');
      }
      if (!ok) fail(path(key), "must be one of " + list + ", got \"" + escape_bytes(s) + "\"");
    }
    return s;
  }
  /// A name (of the scene or an object): any text without control characters.
  std::string name(const std::string& key, const std::string& def) {
    const std::string s = string(key, def);
    for (const char c : s)
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
        fail(path(key), "must not contain control characters, got \"" + escape_bytes(s) + "\"");
    return s;
  }
  Eigen::Vector3d vec3(const std::string& key, const Eigen::Vector3d& def, double limit) {
    const Json* j = get(key);
    if (!j) return def;
    if (!j->is_array() || j->as_array().size() != 3)
      fail(path(key), "must be an array of 3 numbers");
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
      const Json& e = j->as_array()[k];
      if (!e.is_number()) fail(path(key) + "[" + std::to_string(k) + "]", "must be a number");
      v[k] = e.as_number();
      if (!(std::abs(v[k]) <= limit))
        fail(path(key) + "[" + std::to_string(k) + "]", "magnitude above " + fmt(limit));
    }
    return v;
  }

  void finish() const {
    for (const auto& [key, value] : *m_obj)
      if (!m_used.count(key)) fail(path(escape_bytes(key)), "unknown field");
  }

  static std::string fmt(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }

 private:
  const Json::Object* m_obj = nullptr;
  std::string m_path;
  const std::string& m_source;
  std::set<std::string> m_used;
};

constexpr double kInf = std::numeric_limits<double>::infinity();

fem::Material parse_material(Fields& f) {
  fem::Material m;  // fields left out keep fem::Material's defaults
  const std::string model = f.string("model", fem::to_string(m.model),
                                     {"linear", "corotational", "stvk", "stable_neo_hookean"});
  m.model = model == "linear"         ? fem::MaterialModel::Linear
            : model == "corotational" ? fem::MaterialModel::Corotational
            : model == "stvk"         ? fem::MaterialModel::StVK
                                      : fem::MaterialModel::StableNeoHookean;
  m.young = f.number("young", m.young, 0, 1e12, true);
  m.poisson = f.number("poisson", m.poisson, -1, 0.5, true);
  if (m.poisson >= 0.5 || m.poisson <= -1)
    f.fail(f.path("poisson"), "must be in (-1, 0.5), got " + Fields::fmt(m.poisson));
  m.density = f.number("density", m.density, 0, 1e6, true);
  return m;
}

ObjectSpec parse_object(const Json& j, const std::string& path, const std::string& source) {
  Fields f(j, path, source);
  ObjectSpec o;
  o.name = f.name("name", path);
  const std::string mesh = f.string("mesh", ""), asset = f.string("asset", "");
  const Json* prim = f.get("primitive");
  const int sources = !mesh.empty() + !asset.empty() + (prim != nullptr);
  if (sources != 1)
    f.fail(path, "needs exactly one of \"mesh\", \"asset\" or \"primitive\" (got " +
                     std::to_string(sources) + ")");
  o.mesh = mesh;
  o.asset = asset;
  if (prim) {
    Fields p(*prim, f.path("primitive"), source);
    PrimitiveSpec ps;
    ps.type = p.string("type", "sphere", {"sphere", "box"});
    ps.radius = p.number("radius", ps.radius, 0, 1e3, true);
    ps.extent = p.vec3("extent", ps.extent, 1e3);
    if (ps.extent.minCoeff() <= 0) p.fail(p.path("extent"), "sides must be positive");
    ps.subdivisions = p.integer("subdivisions", ps.subdivisions, 0, 6);
    ps.cells = p.integer("cells", ps.cells, 1, 64);
    p.finish();
    o.primitive = ps;
  }
  if (const Json* pre = f.get("preprocess")) {
    Fields p(*pre, f.path("preprocess"), source);
    o.preprocess.coarse_tets = p.integer("coarse_tets", o.preprocess.coarse_tets, 10, 1000000);
    o.preprocess.tree_depth = p.integer("tree_depth", o.preprocess.tree_depth, 0, 7);
    o.preprocess.tree_branching = p.integer("tree_branching", o.preprocess.tree_branching, 2, 64);
    o.preprocess.tree_builder =
        p.string("tree_builder", o.preprocess.tree_builder, {"medial", "octree"});
    o.preprocess.tree_fit = p.string("tree_fit", o.preprocess.tree_fit, {"light", "full", "shell"});
    p.finish();
  }
  o.size = f.number("size", 0, 0, 1e4);
  o.position = f.vec3("position", o.position, 1e6);
  o.rotation_deg = f.vec3("rotation_deg", o.rotation_deg, 1e4);
  o.velocity = f.vec3("velocity", o.velocity, 1e4);
  const std::string kind = f.string("kind", "deformable", {"deformable", "rigid", "static"});
  o.kind = kind == "deformable" ? ObjectKind::Deformable
           : kind == "rigid"    ? ObjectKind::Rigid
                                : ObjectKind::Static;
  o.analytic_collider = f.string("collider", "analytic", {"analytic", "spheres"}) == "analytic";
  if (o.kind == ObjectKind::Static && o.velocity.norm() > 0)
    f.fail(f.path("velocity"), "a static object cannot have a velocity");
  if (const Json* mat = f.get("material")) {
    Fields m(*mat, f.path("material"), source);
    o.material = parse_material(m);
    const Json* ray = m.get("rayleigh");
    if (ray) {
      const Eigen::Vector3d def(0, 0, 0);
      if (!ray->is_array() || ray->as_array().size() != 2 || !ray->as_array()[0].is_number() ||
          !ray->as_array()[1].is_number())
        m.fail(m.path("rayleigh"), "must be [alpha, beta], two numbers");
      o.damping.alpha = ray->as_array()[0].as_number();
      o.damping.beta = ray->as_array()[1].as_number();
      if (!(o.damping.alpha >= 0) || !(o.damping.beta >= 0) || o.damping.alpha > 1e6 ||
          o.damping.beta > 1)
        m.fail(m.path("rayleigh"), "needs 0 <= alpha <= 1e6 (1/s) and 0 <= beta <= 1 (s)");
    }
    m.finish();
  }
  const std::string integ =
      f.string("integrator", "rk4", {"rk4", "symplectic_euler", "backward_euler"});
  o.integrator = integ == "rk4"                ? fem::Integrator::RK4
                 : integ == "symplectic_euler" ? fem::Integrator::SymplecticEuler
                                               : fem::Integrator::BackwardEuler;
  if (const Json* fixed = f.get("fixed_nodes")) {
    if (!fixed->is_array()) f.fail(f.path("fixed_nodes"), "must be an array of node indices");
    for (size_t k = 0; k < fixed->as_array().size(); ++k) {
      const Json& e = fixed->as_array()[k];
      if (!e.is_number() || e.as_number() < 0 || e.as_number() != std::floor(e.as_number()) ||
          e.as_number() > 1e9)
        f.fail(f.path("fixed_nodes") + "[" + std::to_string(k) + "]",
               "must be a non-negative integer node index");
      o.fixed_nodes.push_back(static_cast<int>(e.as_number()));
    }
  }
  f.finish();
  return o;
}

CollisionSpec parse_collision(const Json& j, const std::string& source) {
  Fields f(j, "collision", source);
  CollisionSpec c;  // fields left out keep CollisionSpec's defaults
  collision::CollisionRequest& q = c.query;
  const bool has_seconds = f.get("budget_seconds") != nullptr;
  const bool has_tests = f.get("budget_tests") != nullptr;
  q.budget_seconds = f.number("budget_seconds", q.budget_seconds, 0, 1e3, true);
  const bool unlimited = f.boolean("unlimited", false);
  if (unlimited) q.budget_seconds = kInf;
  const double tests = f.number("budget_tests", -1, -1, 1e15);
  if (tests != -1 && (tests < 0 || tests != std::floor(tests)))
    f.fail("collision.budget_tests", "must be a positive integer or -1");
  if (tests == 0)
    f.fail("collision.budget_tests",
           "0 allows no sphere test, so every query would answer with the root pair (whole "
           "objects assumed colliding); give a positive count, or -1 for no limit");
  q.budget_tests = static_cast<int64_t>(tests);
  if (q.budget_tests >= 0 && !has_seconds) q.budget_seconds = kInf;
  // One budget per scene: a second one would silently override the first
  // (budget_tests -1 is "no test budget").
  const bool test_budget = has_tests && tests != -1;
  if (test_budget && has_seconds)
    f.fail("collision.budget_tests and collision.budget_seconds",
           "contradict each other: give one budget (sphere tests for reproducible runs, or "
           "seconds), not both");
  if (unlimited && (test_budget || has_seconds))
    f.fail(std::string("collision.unlimited and collision.") +
               (has_seconds ? "budget_seconds" : "budget_tests"),
           "contradict each other: \"unlimited\": true means no budget");
  const std::string mode =
      f.string("mode", "fifo", {"fifo", "fifo_literal", "depth_first", "priority"});
  q.mode = mode == "depth_first"    ? collision::TraversalMode::DepthFirst
           : mode == "priority"     ? collision::TraversalMode::Priority
           : mode == "fifo_literal" ? collision::TraversalMode::BreadthFirstLiteral
                                    : collision::TraversalMode::BreadthFirstFifo;
  // The paper reads the clock at every test (Fig. 7).
  const int interval = collision::is_literal(q.mode) ? 1 : q.clock_check_interval;
  q.clock_check_interval = f.integer("clock_check_interval", interval, 1, 1 << 20);
  q.max_list_size =
      static_cast<std::size_t>(f.integer("max_list_size", static_cast<int>(q.max_list_size), 8, 1 << 28));
  const int cap = f.integer("depth_cap", -1, -1, 64);
  if (cap >= 0) q.depth_cap = cap;
  c.temporal_coherence = f.boolean("temporal_coherence", c.temporal_coherence);
  q.parent_filter = f.boolean("parent_filter", q.parent_filter);
  if (q.parent_filter && collision::is_literal(q.mode))
    f.fail("collision.parent_filter",
           "the literal Fig. 7 mode (\"fifo_literal\") tests pairs when popped and has no parent "
           "filter; use \"fifo\"");
  c.layered = f.boolean("layered", c.layered);
  c.single_cycle_when_apart = f.boolean("single_cycle_when_apart", c.single_cycle_when_apart);
  c.swept = f.boolean("swept", c.swept);
  c.cycle_motion = f.number("cycle_motion", c.cycle_motion, 0, 1e3, true);
  c.midpoint = f.boolean("midpoint", c.midpoint);
  c.passive = f.boolean("passive", c.passive);
  const bool paper_update = c.update.mode == collision::SphereUpdateMode::PaperRatio;
  const std::string upd =
      f.string("sphere_update", paper_update ? "paper" : "conservative", {"paper", "conservative"});
  c.update.mode = upd == "paper" ? collision::SphereUpdateMode::PaperRatio
                                 : collision::SphereUpdateMode::DisplacementBound;
  c.update.margin = f.number("sphere_margin", c.update.margin, 0, 1e3);
  c.contact.stiffness = f.number("stiffness", c.contact.stiffness, 0, 1e12, true);
  const coupling::ContactDistribution d0 = c.contact.distribution;
  const std::string dist =
      f.string("distribution",
               d0 == coupling::ContactDistribution::PaperAverage       ? "paper_average"
               : d0 == coupling::ContactDistribution::PartitionOfUnity ? "partition_of_unity"
                                                                        : "mass_weighted",
               {"mass_weighted", "partition_of_unity", "paper_average"});
  c.contact.distribution = dist == "paper_average" ? coupling::ContactDistribution::PaperAverage
                           : dist == "partition_of_unity"
                               ? coupling::ContactDistribution::PartitionOfUnity
                               : coupling::ContactDistribution::MassWeighted;
  c.contact.use_untested = f.boolean("use_untested", c.contact.use_untested);
  const bool untested = c.on_interrupt == InterruptedResponse::Untested;
  c.on_interrupt = f.string("on_interrupt", untested ? "untested" : "previous",
                            {"untested", "previous"}) == "untested"
                       ? InterruptedResponse::Untested
                       : InterruptedResponse::Previous;
  c.previous_max_age = f.number("previous_max_age", c.previous_max_age, 0, kInf);
  f.finish();
  return c;
}

}  // namespace

Scene parse_scene(const Json& json, const std::string& source,
                  const std::filesystem::path& base_dir) {
  Fields f(json, "", source);
  Scene s;
  s.base_dir = base_dir;
  s.name = f.name("name", "scene");
  s.frames = f.integer("frames", s.frames, 1, 100000000);
  s.world.frame_rate = f.number("frame_rate", s.world.frame_rate, 0, 1e5, true);
  s.world.gravity = f.vec3("gravity", s.world.gravity, 1e4);
  s.world.target_fps = f.number("target_fps", s.world.target_fps, 0, 1e5);
  s.world.min_query_budget = f.number("min_query_budget", s.world.min_query_budget, 0, 1, true);
  s.world.threads = f.integer("threads", s.world.threads, 0, 1024);
  const Json* objects = f.get("objects");
  if (!objects || !objects->is_array() || objects->as_array().empty())
    f.fail("objects", "must be a non-empty array of objects");
  for (size_t i = 0; i < objects->as_array().size(); ++i)
    s.objects.push_back(
        parse_object(objects->as_array()[i], "objects[" + std::to_string(i) + "]", source));
  std::set<std::string> names;
  for (size_t i = 0; i < s.objects.size(); ++i)
    if (!names.insert(s.objects[i].name).second)
      f.fail("objects[" + std::to_string(i) + "].name",
             "duplicate object name \"" + escape_bytes(s.objects[i].name) + "\"");
  if (const Json* c = f.get("collision")) s.world.collision = parse_collision(*c, source);
  if (const Json* obs = f.get("obstacles")) {
    if (!obs->is_array()) f.fail("obstacles", "must be an array of obstacles");
    for (size_t k = 0; k < obs->as_array().size(); ++k) {
      const std::string path = "obstacles[" + std::to_string(k) + "]";
      Fields o(obs->as_array()[k], path, source);
      coupling::Obstacle ob;
      const std::string type = o.string("type", "plane", {"plane", "box"});
      if (type == "plane") {
        ob.type = coupling::Obstacle::Type::Plane;
        ob.point = o.vec3("point", ob.point, 1e6);
        ob.normal = o.vec3("normal", ob.normal, 1e6);
        if (!(ob.normal.norm() > 0)) o.fail(o.path("normal"), "must be a non-zero vector");
        ob.normal.normalize();
      } else {
        ob.type = coupling::Obstacle::Type::Box;
        ob.point = o.vec3("center", ob.point, 1e6);
        const Eigen::Vector3d extent = o.vec3("extent", 2 * ob.half_extents, 1e6);
        if (!(extent.minCoeff() > 0)) o.fail(o.path("extent"), "sides must be positive");
        ob.half_extents = extent / 2;
        ob.axes = coupling::rotation_matrix(o.vec3("rotation_deg", Eigen::Vector3d::Zero(), 1e4));
      }
      o.finish();
      s.world.obstacles.push_back(ob);
    }
  }
  if (const Json* o = f.get("output")) {
    Fields out(*o, "output", source);
    s.output.csv = out.boolean("csv", true);
    s.output.vtu_every = out.integer("vtu_every", 0, 0, 1000000);
    s.output.dense = out.boolean("dense", true);
    s.output.spheres = out.boolean("spheres", true);
    s.world.exact_reference = out.boolean("exact_reference", false);
    out.finish();
  }
  f.finish();
  // Resolve paths: the scene's folder, the working folder, $ICD_DATA_DIR,
  // then (build tree only) the repository root (locations.hpp).
  for (ObjectSpec& o : s.objects)
    for (std::filesystem::path* p : {&o.mesh, &o.asset}) *p = resolve_input(*p, base_dir);
  return s;
}

coupling::WorldSettings world_settings(const Scene& scene) {
  coupling::WorldSettings w = scene.world;
  w.dense_meshes = scene.output.vtu_every > 0 && scene.output.dense;
  return w;
}

Scene load_scene(const std::filesystem::path& path) {
  const Json j = read_json_file(path.string());
  return parse_scene(j, path.string(), path.parent_path());
}

}  // namespace icd::runner
