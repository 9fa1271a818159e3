#include "experiments/runner/scene.hpp"
#include "experiments/runner/locations.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <set>
#include <string_view>

#include <icd/config.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/input_file.hpp>

namespace icd::runner {
namespace {

constexpr int kMaxDepth = 64;
constexpr int64_t kMaxValues = int64_t{1} << 20;
constexpr int kMaxIncludeDepth = 8;

// "<source>:<line>:<col>" of byte offset `pos` of `text`.
std::string located(const std::string& source, std::string_view text, std::size_t pos) {
  int line = 1, col = 1;
  for (size_t i = 0; i < pos && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return source + ":" + std::to_string(line) + ":" + std::to_string(col);
}

// Tracks where the parser is (for duplicate keys), how deep and how many values.
class ParseGuard {
  struct Frame {
    bool object;
    long index;
    std::string key;
    std::set<std::string> keys;
  };

 public:
  explicit ParseGuard(const std::string& source) : m_source(source) {}

  bool operator()(int depth, Json::parse_event_t event, Json& parsed) {
    using E = Json::parse_event_t;
    if (event == E::object_start || event == E::array_start || event == E::value) {
      if (++m_values > kMaxValues)
        throw InputError(m_source + ": more than " + std::to_string(kMaxValues) +
                         " values (not a scene file?)");
      if (!m_stack.empty() && !m_stack.back().object) ++m_stack.back().index;
    }
    if (event == E::object_start || event == E::array_start) {
      if (depth >= kMaxDepth)
        throw InputError(m_source + ": " + path() + ": nesting deeper than " +
                         std::to_string(kMaxDepth) + " levels");
      m_stack.push_back({event == E::object_start, -1, {}, {}});
    } else if (event == E::object_end || event == E::array_end) {
      if (!m_stack.empty()) m_stack.pop_back();
    } else if (event == E::key) {
      Frame& f = m_stack.back();
      f.key = parsed.get<std::string>();
      if (!f.keys.insert(f.key).second)
        throw InputError(m_source + ": " + path() + ": duplicate key \"" + escape_bytes(f.key) +
                         "\"");
    }
    return true;
  }

 public:
  /// Path of the value being read when the parser stopped (a number beyond
  /// the double range: its key was seen, its value event was not).
  std::string pending_path() const { return path(true); }

 private:
  std::string path(bool pending = false) const {
    std::string p;
    for (size_t i = 0; i < m_stack.size(); ++i) {
      const Frame& f = m_stack[i];
      if (f.object && f.key.empty() && f.keys.empty()) break;
      const long index = f.index + (pending && i + 1 == m_stack.size() ? 1 : 0);
      if (f.object)
        p += (p.empty() ? "" : ".") + escape_bytes(f.key);
      else if (index >= 0)
        p += "[" + std::to_string(index) + "]";
    }
    return p.empty() ? "<root>" : p;
  }

  const std::string& m_source;
  std::vector<Frame> m_stack;
  int64_t m_values = 0;
};

// Deep merge: `over` wins; objects merge key by key.
void merge_into(Json& base, const Json& over) {
  if (!base.is_object() || !over.is_object()) {
    base = over;
    return;
  }
  for (auto it = over.begin(); it != over.end(); ++it) {
    auto b = base.find(it.key());
    if (b == base.end())
      base[it.key()] = it.value();
    else
      merge_into(*b, it.value());
  }
}

Json read_with_includes(const std::filesystem::path& path, std::vector<std::filesystem::path>& chain) {
  const std::string source = path.string();
  std::error_code ec;
  std::filesystem::path id = std::filesystem::weakly_canonical(path, ec);
  if (ec) id = std::filesystem::absolute(path, ec).lexically_normal();
  for (const auto& c : chain)
    if (c == id) {
      std::string list;
      for (const auto& d : chain) list += escape_bytes(d.string(), 4096) + " -> ";
      throw InputError(escape_bytes(source, 4096) + ": include: cycle " + list +
                       escape_bytes(id.string(), 4096));
    }
  if (static_cast<int>(chain.size()) > kMaxIncludeDepth)
    throw InputError(escape_bytes(source, 4096) + ": include: nested more than " +
                     std::to_string(kMaxIncludeDepth) + " deep");
  Json j = read_json_file(source);
  if (!j.is_object() || !j.contains("include")) return j;
  const Json inc = j["include"];
  j.erase("include");
  std::vector<std::string> files;
  if (inc.is_string()) {
    files.push_back(inc.get<std::string>());
  } else if (inc.is_array()) {
    for (size_t k = 0; k < inc.size(); ++k) {
      if (!inc[k].is_string())
        throw InputError(escape_bytes(source, 4096) + ": include[" + std::to_string(k) +
                         "]: must be a file path (a string)");
      files.push_back(inc[k].get<std::string>());
    }
  } else {
    throw InputError(escape_bytes(source, 4096) +
                     ": include: must be a file path or an array of file paths");
  }
  chain.push_back(id);
  Json merged = Json::object();
  for (const std::string& f : files) {
    if (f.empty()) throw InputError(escape_bytes(source, 4096) + ": include: empty path");
    std::filesystem::path p(f);
    if (p.is_relative()) p = path.parent_path() / p;
    merge_into(merged, read_with_includes(p, chain));
  }
  chain.pop_back();
  merge_into(merged, j);
  return merged;
}

// Reads the fields of one JSON object, remembering the field path for
// messages, and rejects fields nobody asked for.
class Fields {
 public:
  Fields(const Json& j, std::string path, const std::string& source)
      : m_path(std::move(path)), m_source(source) {
    if (!j.is_object()) fail(m_path, std::string("must be an object, got ") + j.type_name());
    m_obj = &j;
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
    return it == m_obj->end() ? nullptr : &*it;
  }

  double number(const std::string& key, double def, double lo, double hi, bool lo_open = false) {
    const Json* j = get(key);
    if (!j) return def;
    if (!j->is_number()) fail(path(key), std::string("must be a number, got ") + j->type_name());
    const double v = j->get<double>();
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
    if (!j->is_boolean()) fail(path(key), std::string("must be true or false, got ") + j->type_name());
    return j->get<bool>();
  }
  std::string string(const std::string& key, const std::string& def,
                     const std::vector<std::string>& allowed = {}) {
    const Json* j = get(key);
    if (!j) return def;
    if (!j->is_string()) fail(path(key), std::string("must be a string, got ") + j->type_name());
    const std::string& s = j->get_ref<const std::string&>();
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
    return vec3_of(*j, path(key), limit);
  }
  Eigen::Vector3d vec3_of(const Json& j, const std::string& at, double limit) const {
    if (!j.is_array() || j.size() != 3) fail(at, "must be an array of 3 numbers");
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
      const Json& e = j[static_cast<size_t>(k)];
      if (!e.is_number()) fail(at + "[" + std::to_string(k) + "]", "must be a number");
      v[k] = e.get<double>();
      if (!(std::abs(v[k]) <= limit))
        fail(at + "[" + std::to_string(k) + "]", "magnitude above " + fmt(limit));
    }
    return v;
  }

  void finish() const {
    for (auto it = m_obj->begin(); it != m_obj->end(); ++it)
      if (!m_used.count(it.key())) {
        std::string hint;  // the closest known field, if it is a likely typo
        size_t best = 3;
        for (const std::string& k : m_used) {
          const size_t d = edit_distance(it.key(), k);
          if (d < best && d < k.size()) {
            best = d;
            hint = " (did you mean \"" + k + "\"?)";
          }
        }
        fail(path(escape_bytes(it.key())), "unknown field" + hint);
      }
  }

  static size_t edit_distance(const std::string& a, const std::string& b) {
    if (a.size() > 64 || b.size() > 64) return std::max(a.size(), b.size());
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
      size_t diag = row[0];
      row[0] = i;
      for (size_t j = 1; j <= b.size(); ++j) {
        const size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1])});
        diag = up;
      }
    }
    return row[b.size()];
  }

  static std::string fmt(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }

 private:
  const Json* m_obj = nullptr;
  std::string m_path;
  const std::string& m_source;
  std::set<std::string> m_used;
};

constexpr double kInf = std::numeric_limits<double>::infinity();

// One selector {"box": ...} | {"plane": ...} | {"near": ...}, or an array of them.
std::vector<RegionSelector> parse_regions(const Json& j, const std::string& at,
                                          const std::string& source) {
  std::vector<RegionSelector> out;
  if (j.is_array()) {
    if (j.empty()) throw InputError(source + ": " + at + ": must not be an empty array");
    for (size_t k = 0; k < j.size(); ++k) {
      const std::string item = at + "[" + std::to_string(k) + "]";
      if (!j[k].is_object()) throw InputError(source + ": " + item + ": must be a region object");
      auto r = parse_regions(j[k], item, source);
      out.insert(out.end(), r.begin(), r.end());
    }
    return out;
  }
  Fields f(j, at, source);
  const Json *box = f.get("box"), *plane = f.get("plane"), *near = f.get("near");
  if ((box != nullptr) + (plane != nullptr) + (near != nullptr) != 1)
    f.fail(at, "needs exactly one of \"box\", \"plane\" or \"near\"");
  f.finish();
  RegionSelector r;
  if (box) {
    Fields b(*box, f.path("box"), source);
    r.type = RegionSelector::Type::Box;
    if (!b.get("min") || !b.get("max")) b.fail(f.path("box"), "needs \"min\" and \"max\"");
    r.a = b.vec3("min", r.a, 1e6);
    r.b = b.vec3("max", r.b, 1e6);
    if (!(r.a.array() <= r.b.array()).all()) b.fail(b.path("max"), "must be >= min in every coordinate");
    b.finish();
    r.field = source + ": " + f.path("box");
  } else if (plane) {
    Fields p(*plane, f.path("plane"), source);
    r.type = RegionSelector::Type::Plane;
    if (!p.get("point") || !p.get("normal")) p.fail(f.path("plane"), "needs \"point\" and \"normal\"");
    r.a = p.vec3("point", r.a, 1e6);
    r.b = p.vec3("normal", r.b, 1e6);
    if (!(r.b.norm() > 0)) p.fail(p.path("normal"), "must be a non-zero vector");
    r.b.normalize();
    r.distance = p.number("tolerance", 0, 0, 1e6);
    p.finish();
    r.field = source + ": " + f.path("plane");
  } else {
    Fields n(*near, f.path("near"), source);
    r.type = RegionSelector::Type::Near;
    if (!n.get("point") || !n.get("distance")) n.fail(f.path("near"), "needs \"point\" and \"distance\"");
    r.a = n.vec3("point", r.a, 1e6);
    r.distance = n.number("distance", 0, 0, 1e6);
    n.finish();
    r.field = source + ": " + f.path("near");
  }
  out.push_back(r);
  return out;
}

MotionSpec parse_motion(const Json& j, const std::string& at, const std::string& source) {
  Fields f(j, at, source);
  f.string("interpolation", "linear", {"linear"});
  const Json* keys = f.get("keyframes");
  if (!keys || !keys->is_array() || keys->empty())
    f.fail(f.path("keyframes"), "must be a non-empty array of keyframes");
  if (keys->size() > 100000) f.fail(f.path("keyframes"), "more than 100000 keyframes");
  MotionSpec m;
  for (size_t k = 0; k < keys->size(); ++k) {
    Fields key((*keys)[k], f.path("keyframes") + "[" + std::to_string(k) + "]", source);
    coupling::Keyframe kf;
    if (!key.get("t") || !key.get("position"))
      key.fail(f.path("keyframes") + "[" + std::to_string(k) + "]", "needs \"t\" and \"position\"");
    kf.t = key.number("t", 0, 0, 1e9);
    if (k > 0 && !(kf.t > m.keys.back().t))
      key.fail(key.path("t"), "must be later than the previous key's (" + Fields::fmt(m.keys.back().t) +
                                  "), got " + Fields::fmt(kf.t));
    kf.position = key.vec3("position", kf.position, 1e6);
    if (const Json* rot = key.get("rotation")) {
      Fields r(*rot, key.path("rotation"), source);
      const Json* q = r.get("quaternion");
      const Json* axis = r.get("axis");
      const bool angle = r.get("angle_deg") != nullptr;
      if ((q != nullptr) == (axis != nullptr || angle))
        r.fail(key.path("rotation"),
               "needs either \"quaternion\": [w, x, y, z] or \"axis\": [x, y, z] with \"angle_deg\"");
      if (q) {
        if (!q->is_array() || q->size() != 4) r.fail(r.path("quaternion"), "must be [w, x, y, z], four numbers");
        double c[4];
        for (size_t i = 0; i < 4; ++i) {
          if (!(*q)[i].is_number() || !std::isfinite((*q)[i].get<double>()) ||
              std::abs((*q)[i].get<double>()) > 1e6)
            r.fail(r.path("quaternion") + "[" + std::to_string(i) + "]", "must be a finite number");
          c[i] = (*q)[i].get<double>();
        }
        kf.rotation = Eigen::Quaterniond(c[0], c[1], c[2], c[3]);
        if (!(kf.rotation.norm() > 1e-12)) r.fail(r.path("quaternion"), "must not be zero");
        kf.rotation.normalize();
      } else {
        if (!axis || !angle) r.fail(key.path("rotation"), "needs both \"axis\" and \"angle_deg\"");
        const Eigen::Vector3d ax = r.vec3("axis", Eigen::Vector3d::UnitZ(), 1e6);
        if (!(ax.norm() > 0)) r.fail(r.path("axis"), "must be a non-zero vector");
        const double deg = r.number("angle_deg", 0, -1e6, 1e6);
        kf.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(deg * M_PI / 180, ax.normalized()));
      }
      r.finish();
    }
    key.finish();
    m.keys.push_back(kf);
  }
  f.finish();
  return m;
}

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
  o.initial_compression = f.number("initial_compression", 0, 0, 0.95);
  if (o.initial_compression > 0 && o.kind != ObjectKind::Deformable)
    f.fail(f.path("initial_compression"), "only a deformable object can start compressed");
  o.collision_weight = f.number("collision_weight", o.collision_weight, 0, 1e6, true);
  if (o.kind == ObjectKind::Static && o.velocity.norm() > 0)
    f.fail(f.path("velocity"), "a static object cannot have a velocity");
  if (const Json* mat = f.get("material")) {
    Fields m(*mat, f.path("material"), source);
    o.material = parse_material(m);
    const Json* ray = m.get("rayleigh");
    if (ray) {
      const Eigen::Vector3d def(0, 0, 0);
      if (!ray->is_array() || ray->size() != 2 || !(*ray)[0].is_number() || !(*ray)[1].is_number())
        m.fail(m.path("rayleigh"), "must be [alpha, beta], two numbers");
      o.damping.alpha = (*ray)[0].get<double>();
      o.damping.beta = (*ray)[1].get<double>();
      if (!(o.damping.alpha >= 0) || !(o.damping.beta >= 0) || o.damping.alpha > 1e6 ||
          o.damping.beta > 1)
        m.fail(m.path("rayleigh"), "needs 0 <= alpha <= 1e6 (1/s) and 0 <= beta <= 1 (s)");
    }
    m.finish();
  }
  if (const Json* fem_fields = f.get("fem")) {
    Fields m(*fem_fields, f.path("fem"), source);
    o.mass_scaling_target = m.number("mass_scaling_target", o.mass_scaling_target, 0, 1);
    m.finish();
  }
  const std::string integ =
      f.string("integrator", "rk4", {"rk4", "symplectic_euler", "backward_euler"});
  o.integrator = integ == "rk4"                ? fem::Integrator::RK4
                 : integ == "symplectic_euler" ? fem::Integrator::SymplecticEuler
                                               : fem::Integrator::BackwardEuler;
  if (const Json* fixed = f.get("fixed_nodes")) {
    if (!fixed->is_array()) f.fail(f.path("fixed_nodes"), "must be an array of node indices");
    for (size_t k = 0; k < fixed->size(); ++k) {
      const Json& e = (*fixed)[k];
      const double v = e.is_number() ? e.get<double>() : -1;
      if (!e.is_number() || v < 0 || v != std::floor(v) || v > 1e9)
        f.fail(f.path("fixed_nodes") + "[" + std::to_string(k) + "]",
               "must be a non-negative integer node index");
      o.fixed_nodes.push_back(static_cast<int>(v));
    }
  }
  if (const Json* fixed = f.get("fixed")) o.fixed_regions = parse_regions(*fixed, f.path("fixed"), source);
  if (const Json* loads = f.get("loads")) {
    if (!loads->is_array()) f.fail(f.path("loads"), "must be an array of loads");
    if (o.kind != ObjectKind::Deformable)
      f.fail(f.path("loads"), "only a deformable object takes loads");
    for (size_t k = 0; k < loads->size(); ++k) {
      const std::string at = f.path("loads") + "[" + std::to_string(k) + "]";
      Fields l((*loads)[k], at, source);
      LoadSpec ls;
      const Json* region = l.get("region");
      if (!region) l.fail(at, "needs a \"region\"");
      ls.region = parse_regions(*region, l.path("region"), source);
      const bool per_node = l.get("force_per_node") != nullptr, total = l.get("total_force") != nullptr;
      if (per_node == total)
        l.fail(at, "needs exactly one of \"force_per_node\" and \"total_force\" (N)");
      ls.total = total;
      ls.force = l.vec3(total ? "total_force" : "force_per_node", ls.force, 1e9);
      l.finish();
      o.loads.push_back(ls);
    }
  }
  if (const Json* motion = f.get("motion")) {
    if (o.kind != ObjectKind::Rigid)
      f.fail(f.path("motion"), "only a rigid (\"kind\": \"rigid\") object follows a motion");
    if (o.velocity.norm() > 0)
      f.fail(f.path("motion"), "a rigid object moves with its \"velocity\" or its \"motion\", not both");
    o.motion = parse_motion(*motion, f.path("motion"), source);
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
  c.predict_contact = f.boolean("predict_contact", c.predict_contact);
  c.swept = f.boolean("swept", c.swept);
  const std::string split = f.string(
      "budget_split",
      c.budget_split == BudgetSplit::Priority   ? "priority"
      : c.budget_split == BudgetSplit::Cheapest ? "cheapest"
                                                : "even",
      {"even", "priority", "cheapest"});
  c.budget_split = split == "priority"   ? BudgetSplit::Priority
                   : split == "cheapest" ? BudgetSplit::Cheapest
                                         : BudgetSplit::Even;
  c.cycle_motion = f.number("cycle_motion", c.cycle_motion, 0, 1e3, true);
  c.midpoint = f.boolean("midpoint", c.midpoint);
  c.passive = f.boolean("passive", c.passive);
  c.node_rate_cap = f.boolean("node_rate_cap", c.node_rate_cap);
  c.cycles_at_fem_step = f.boolean("cycles_at_fem_step", c.cycles_at_fem_step);
  c.deep_step_ratio = f.number("deep_step_ratio", c.deep_step_ratio, 0, 1e3);
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
  if (f.get("include"))
    f.fail("include", "includes are resolved when a scene is read from a file (load_scene)");
  const Json* objects = f.get("objects");
  if (!objects || !objects->is_array() || objects->empty())
    f.fail("objects", "must be a non-empty array of objects");
  for (size_t i = 0; i < objects->size(); ++i)
    s.objects.push_back(parse_object((*objects)[i], "objects[" + std::to_string(i) + "]", source));
  std::set<std::string> names;
  for (size_t i = 0; i < s.objects.size(); ++i)
    if (!names.insert(s.objects[i].name).second)
      f.fail("objects[" + std::to_string(i) + "].name",
             "duplicate object name \"" + escape_bytes(s.objects[i].name) + "\"");
  if (const Json* c = f.get("collision")) s.world.collision = parse_collision(*c, source);
  if (const Json* obs = f.get("obstacles")) {
    if (!obs->is_array()) f.fail("obstacles", "must be an array of obstacles");
    for (size_t k = 0; k < obs->size(); ++k) {
      const std::string path = "obstacles[" + std::to_string(k) + "]";
      const Json& entry = (*obs)[k];
      coupling::Obstacle ob;
      if (entry.is_object() && entry.contains("plane")) {  // {"plane": {"point", "normal"}}
        Fields w(entry, path, source);
        Fields o(*w.get("plane"), path + ".plane", source);
        w.finish();
        ob.type = coupling::Obstacle::Type::Plane;
        ob.point = o.vec3("point", ob.point, 1e6);
        ob.normal = o.vec3("normal", ob.normal, 1e6);
        if (!(ob.normal.norm() > 0)) o.fail(o.path("normal"), "must be a non-zero vector");
        ob.normal.normalize();
        o.finish();
        s.world.obstacles.push_back(ob);
        continue;
      }
      Fields o(entry, path, source);
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

Json parse_json(std::string_view text, const std::string& source) {
  text = strip_utf8_bom(text);
  if (text.size() >= 2 && ((text[0] == '\xff' && text[1] == '\xfe') || (text[0] == '\xfe' && text[1] == '\xff')))
    throw InputError(located(source, text, 0) +
                     ": unexpected character '" + escape_bytes(text.substr(0, 1)) +
                     "': a UTF-16 byte-order mark (scene files are UTF-8)");
  // nlohmann-json ends the input at a NUL byte (anything after it would be
  // silently ignored): refuse it.
  if (const size_t nul = text.find('\0'); nul != std::string_view::npos)
    throw InputError(located(source, text, nul) +
                     ": unexpected character '\\x00' (a NUL byte; not a JSON text file?)");
  ParseGuard guard(source);
  try {
    return Json::parse(text, std::ref(guard), /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const Json::parse_error& e) {
    // "[json.exception.parse_error.101] parse error at line 1, column 5: syntax error ..."
    std::string what = e.what();
    const size_t colon = what.find(": ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    const size_t at = e.byte > 0 ? e.byte - 1 : 0;
    throw InputError(located(source, text, at) + ": " + escape_bytes(what, 300));
  } catch (const Json::out_of_range& e) {
    if (e.id != 406) throw;
    // A number beyond the double range (nlohmann refuses it while parsing):
    // name the field, as the field readers do for an infinite value.
    throw InputError(source + ": " + guard.pending_path() +
                     ": must be a finite number, got one beyond the double range (about 1.8e308)");
  }
}

Json read_json_file(const std::string& path) {
  return parse_json(read_input_file(path, file_limits::kScene, "scene file"), path);
}

Json read_scene_json(const std::filesystem::path& path) {
  std::vector<std::filesystem::path> chain;
  return read_with_includes(path, chain);
}

void apply_overrides(Json& json, const std::vector<std::string>& overrides) {
  for (const std::string& o : overrides) {
    const std::string shown = "--set " + escape_bytes(o, 300);
    const size_t eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(shown + ": expected key=value (e.g. objects.1.material.young=2e5)");
    const std::string key = o.substr(0, eq), text = o.substr(eq + 1);
    Json value = Json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (value.is_discarded()) value = text;  // not JSON: a string
    Json* at = &json;
    Json* parent = nullptr;  // the object holding the last key (null: none)
    std::string path, last;
    size_t start = 0;
    while (true) {
      const size_t dot = key.find('.', start);
      const std::string part = key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
      if (part.empty()) throw InputError(shown + ": empty part in the key");
      if (at->is_array()) {
        const bool digits = part.find_first_not_of("0123456789") == std::string::npos && part.size() < 10;
        if (!digits)
          throw InputError(shown + ": " + (path.empty() ? "<root>" : path) +
                           " is an array: expected an index, got \"" + escape_bytes(part) + "\"");
        const size_t idx = std::stoul(part);
        if (idx >= at->size())
          throw InputError(shown + ": " + path + "[" + part + "]: index past the end (" + path +
                           " has " + std::to_string(at->size()) + " entries)");
        path += "[" + part + "]";
        parent = nullptr;
        at = &(*at)[idx];
      } else if (at->is_object() || at->is_null()) {
        if (at->is_null()) *at = Json::object();
        path += (path.empty() ? "" : ".") + part;
        parent = at;
        last = part;
        at = &(*at)[part];
      } else {
        throw InputError(shown + ": " + path + " is a " + at->type_name() +
                         ", not an object or an array");
      }
      if (dot == std::string::npos) break;
      start = dot + 1;
    }
    if (value.is_null() && parent)  // key=null removes the key (as a JSON merge patch does)
      parent->erase(last);
    else
      *at = std::move(value);
  }
}

Scene load_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  Json j = read_scene_json(path);
  apply_overrides(j, overrides);
  return parse_scene(j, path.string(), path.parent_path());
}

bool RegionSelector::contains(const Eigen::Vector3d& x) const {
  switch (type) {
    case Type::Box:
      return (x.array() >= a.array()).all() && (x.array() <= b.array()).all();
    case Type::Plane:
      return (x - a).dot(b) <= distance;
    case Type::Near:
      return (x - a).norm() <= distance;
  }
  return false;
}

std::vector<int> select_nodes(const std::vector<RegionSelector>& regions, const MatX3d& positions) {
  std::vector<char> in(static_cast<size_t>(positions.rows()), 0);
  for (const RegionSelector& r : regions) {
    int count = 0;
    for (Eigen::Index v = 0; v < positions.rows(); ++v)
      if (r.contains(positions.row(v).transpose())) {
        in[static_cast<size_t>(v)] = 1;
        ++count;
      }
    if (count == 0) {
      const Eigen::Vector3d lo = positions.colwise().minCoeff(), hi = positions.colwise().maxCoeff();
      throw InputError(r.field + ": selects no coarse node (the object's " +
                       std::to_string(positions.rows()) + " coarse nodes span [" +
                       Fields::fmt(lo.x()) + ", " + Fields::fmt(lo.y()) + ", " + Fields::fmt(lo.z()) +
                       "] to [" + Fields::fmt(hi.x()) + ", " + Fields::fmt(hi.y()) + ", " +
                       Fields::fmt(hi.z()) + "])");
    }
  }
  std::vector<int> out;
  for (size_t v = 0; v < in.size(); ++v)
    if (in[v]) out.push_back(static_cast<int>(v));
  return out;
}

MatX3d apply_regions(const ObjectSpec& spec, coupling::ObjectSetup& setup, const MatX3d& coarse) {
  if (!spec.fixed_regions.empty()) {
    std::set<int> fixed(setup.fixed_nodes.begin(), setup.fixed_nodes.end());
    for (int v : select_nodes(spec.fixed_regions, coarse))
      if (fixed.insert(v).second) setup.fixed_nodes.push_back(v);
  }
  if (spec.motion) setup.motion = coupling::KeyframeMotion(spec.motion->keys, spec.position).function();
  if (spec.loads.empty()) return {};
  MatX3d forces = MatX3d::Zero(coarse.rows(), 3);
  for (const LoadSpec& l : spec.loads) {
    const std::vector<int> nodes = select_nodes(l.region, coarse);
    const Eigen::Vector3d f = l.total ? Eigen::Vector3d(l.force / static_cast<double>(nodes.size())) : l.force;
    for (int v : nodes) forces.row(v) += f.transpose();
  }
  return forces;
}

}  // namespace icd::runner
