#include "experiments/runner/run.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <fstream>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <thread>

#include "experiments/runner/object_asset.hpp"
#include <icd/config.hpp>
#include <icd/mesh/io/atomic_write.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/vtk_writer.hpp>

namespace icd::runner {
namespace {

// File-name stems of the objects' outputs: file_name_from(name), made unique
// (names that differ only in unsafe characters would share files).
std::vector<std::string> object_file_names(const World& world) {
  std::vector<std::string> names;
  std::set<std::string> used;
  for (size_t i = 0; i < world.objects().size(); ++i) {
    std::string n = file_name_from(world.objects()[i].setup.name);
    for (int k = 2; used.count(n); ++k)
      n = file_name_from(world.objects()[i].setup.name) + "_" + std::to_string(k);
    used.insert(n);
    names.push_back(n);
  }
  return names;
}

VtuOptions binary_at(double time) {
  VtuOptions o;
  o.encoding = VtuEncoding::Binary;
  o.time = time;
  return o;
}

// Velocities of the coarse nodes: the FEM state of a deformable object, the
// motion over the frame (positions before it, `before`) of any other.
MatX3d node_velocities(const coupling::RuntimeObject& o, const MatX3d& before, double dt) {
  if (o.sim) return o.sim->velocities();
  if (before.rows() == o.positions.rows() && dt > 0) return (o.positions - before) / dt;
  return MatX3d::Zero(o.positions.rows(), 3);
}

// Volume of each tet now over its rest volume (< 0: inverted).
Eigen::MatrixXd volume_ratios(const MatX3d& x, const MatX3d& rest, const MatX4i& T) {
  Eigen::MatrixXd r(T.rows(), 1);
  const auto vol6 = [&](const MatX3d& p, Eigen::Index t) {
    const Eigen::Vector3d a = p.row(T(t, 0)), b = p.row(T(t, 1)), c = p.row(T(t, 2)),
                          d = p.row(T(t, 3));
    return (b - a).cross(c - a).dot(d - a);
  };
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const double v0 = vol6(rest, t);
    r(t, 0) = v0 != 0 ? vol6(x, t) / v0 : 0.0;
  }
  return r;
}

// Writes one output frame into `dir` and lists its files in `pvd` (one part
// per object mesh and per pair side, in the order of output_parts).
void write_frame_vtu(World& world, const Scene& scene, int frame, const std::filesystem::path& dir,
                     const std::vector<std::string>& file_names,
                     const std::vector<MatX3d>& before, std::vector<PvdEntry>& pvd) {
  const double t = (frame + 1) / scene.world.frame_rate;  // the state at the end of the frame
  const double dt = 1.0 / scene.world.frame_rate;
  auto& objects = world.objects();
  int part = 0;
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, "_%06d.vtu", frame);
  const VtuOptions bin = binary_at(t);
  for (size_t k = 0; k < objects.size(); ++k) {
    coupling::RuntimeObject& o = objects[k];
    TetMesh coarse = o.asset.coarse;
    coarse.V = o.positions;
    const Eigen::Index n = o.positions.rows();
    const MatX3d zero = MatX3d::Zero(n, 3);
    const std::vector<PointDataArray> pd = {
        {"displacement", o.positions - o.rest},
        {"velocity", node_velocities(o, before[k], dt)},
        {"contact_force", o.contact_forces.rows() == n ? MatX3d(o.contact_forces) : zero},
        {"external_force", o.external_forces.rows() == n ? MatX3d(o.external_forces) : zero}};
    VtuOptions copt = bin;
    copt.cell_data = {{"volume_ratio", volume_ratios(o.positions, o.rest, coarse.T)}};
    const std::string cname = file_names[k] + "_coarse" + suffix;
    write_vtu_tet_mesh(dir / cname, coarse, pd, copt);
    pvd.push_back({t, cname, part++});
    if (o.plan.dense_update && scene.output.dense) {
      SurfaceMesh dense{o.dense, o.asset.dense.F};
      const std::string dname = file_names[k] + "_dense" + suffix;
      const std::vector<PointDataArray> dpd = {{"displacement", o.dense - o.asset.dense.V}};
      write_vtu_surface_mesh(dir / dname, dense, dpd, bin);
      pvd.push_back({t, dname, part++});
    }
  }
  if (scene.output.spheres && !world.plan().pairs.empty()) {
    // The spheres used for the contact response: colliding and untested pairs.
    for (size_t p = 0; p < world.plan().pairs.size(); ++p) {
      const auto [i, j] = world.plan().pairs[p];
      for (int side = 0; side < 2; ++side) {
        const std::string name =
            file_names[side ? j : i] + "_contact_spheres_pair" + std::to_string(p) + suffix;
        write_contact_spheres(world, p, side, dir / name, bin);
        pvd.push_back({t, name, part++});
      }
    }
  }
}

// Writes each object's whole sphere tree as placed at the start (a sphere set
// with point arrays "level" and "leaf"), <name>_tree.vtu: the levels people
// look at (scripts/plot_run.py, ParaView's Threshold on "level").
void write_trees(World& world, const std::filesystem::path& dir,
                 const std::vector<std::string>& file_names) {
  for (size_t k = 0; k < world.objects().size(); ++k) {
    const collision::SphereTree& tree = world.objects()[k].asset.spheres;
    const auto n = static_cast<Eigen::Index>(tree.spheres.size());
    if (n == 0) continue;
    SphereSet set{MatX3d(n, 3), Eigen::VectorXd(n)};
    PointDataArray level{"level", Eigen::MatrixXd(n, 1)};
    PointDataArray leaf{"leaf", Eigen::MatrixXd(n, 1)};
    for (Eigen::Index s = 0; s < n; ++s) {
      const collision::Sphere& sp = tree.spheres[static_cast<size_t>(s)];
      set.centers.row(s) << sp.x, sp.y, sp.z;
      set.radii[s] = sp.r;
      level.values(s, 0) = tree.level[static_cast<size_t>(s)];
      leaf.values(s, 0) = tree.is_leaf(static_cast<int>(s)) ? 1.0 : 0.0;
    }
    const PointDataArray arrays[] = {level, leaf};
    write_vtu_sphere_set(dir / (file_names[k] + "_tree.vtu"), set, arrays, binary_at(0.0));
  }
}

std::string format_duration(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  return buf;
}

}  // namespace

// A static box collides as an analytic box obstacle (see make_world).
static bool analytic_box(const ObjectSpec& spec) {
  return spec.kind == ObjectKind::Static && spec.primitive && spec.primitive->type == "box" &&
         spec.analytic_collider;
}

std::vector<coupling::ObjectSetup> object_setups(const Scene& scene) {
  std::vector<coupling::ObjectSetup> setups(scene.objects.begin(), scene.objects.end());
  for (size_t i = 0; i < setups.size(); ++i)
    if (analytic_box(scene.objects[i])) setups[i].sphere_collisions = false;
  return setups;
}

coupling::StagePlan scene_plan(const Scene& scene) {
  return coupling::make_plan(object_setups(scene), world_settings(scene));
}

std::vector<std::string> describe_plan(const Scene& scene) {
  const std::vector<coupling::ObjectSetup> setups = object_setups(scene);
  const coupling::WorldSettings settings = world_settings(scene);
  std::vector<std::string> lines = coupling::make_plan(setups, settings).describe(setups, settings);
  int boxes = 0;
  for (const ObjectSpec& o : scene.objects) boxes += analytic_box(o);
  if (!scene.world.obstacles.empty() || boxes > 0)
    lines.push_back("obstacles: " + std::to_string(scene.world.obstacles.size() + boxes) +
                    " static plane/box obstacle(s) (" + std::to_string(boxes) +
                    " from static box objects), deformable surfaces projected out of them");
  lines.push_back(std::string("output: ") + (scene.output.csv ? "frames.csv" : "no csv") +
                  (scene.output.vtu_every > 0 ? ", VTU/PVD series" : ""));
  return lines;
}

void check_scene_inputs(const Scene& scene) {
  for (const ObjectSpec& spec : scene.objects) check_object_inputs(spec);
}

World make_world(const Scene& scene, const std::filesystem::path& cache_dir,
                 const std::filesystem::path& tool_dir, const ChildLimits& limits) {
  check_scene_inputs(scene);
  std::vector<coupling::WorldObject> objects;
  std::vector<MatX3d> loads;
  objects.reserve(scene.objects.size());
  coupling::WorldSettings settings = world_settings(scene);
  for (const ObjectSpec& spec : scene.objects) {
    coupling::WorldObject o;
    o.setup = spec;
    o.asset = load_object_asset(spec, cache_dir, tool_dir, limits);
    place_object(o.asset, spec);
    loads.push_back(apply_regions(spec, o.setup, o.asset.coarse.V));  // selectors, keyframes
    if (analytic_box(spec)) {
      // A static box collides as what it is, an analytic box obstacle, not
      // through its sphere tree (whose leaves stand out of its faces).
      coupling::Obstacle box;
      box.type = coupling::Obstacle::Type::Box;
      box.point = spec.position;
      box.axes = coupling::rotation_matrix(spec.rotation_deg);
      const MatX3d local = (o.asset.dense.V.rowwise() - spec.position.transpose()) * box.axes;
      box.half_extents = local.cwiseAbs().colwise().maxCoeff().transpose();
      settings.obstacles.push_back(box);
      o.setup.sphere_collisions = false;
    }
    objects.push_back(std::move(o));
  }
  for (const std::string& w : scale_warnings(objects))
    std::fprintf(stderr, "[icd] warning: %s\n", w.c_str());
  World world(std::move(objects), settings);
  for (size_t i = 0; i < loads.size(); ++i)
    if (loads[i].size() > 0) world.set_external_forces(static_cast<int>(i), loads[i]);
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    // "initial_compression": the coarse nodes squeezed along x about their
    // centroid, then released (the first frame starts from this state).
    const double c = scene.objects[i].initial_compression;
    RuntimeObject& o = world.objects()[i];
    if (c <= 0 || !o.sim) continue;
    const double cx = o.rest.col(0).mean();
    MatX3d x = o.rest;
    x.col(0) = (x.col(0).array() - cx) * (1 - c) + cx;
    o.sim->set_positions(x);
    o.positions = x;
  }
  return world;
}

std::vector<std::string> scale_warnings(const std::vector<coupling::WorldObject>& objects) {
  constexpr double kRatio = 100;
  const auto fmt = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::string(buf);
  };
  std::vector<double> size;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const coupling::WorldObject& o : objects) {
    const MatX3d& V = o.asset.dense.V;
    if (V.rows() == 0) {
      size.push_back(0);
      continue;
    }
    const Eigen::Vector3d a = V.colwise().minCoeff(), b = V.colwise().maxCoeff();
    size.push_back((b - a).norm());
    lo = lo.cwiseMin(0.5 * (a + b));
    hi = hi.cwiseMax(0.5 * (a + b));
  }
  const double span = objects.size() >= 2 ? (hi - lo).norm() : 0;
  size_t smallest = 0;
  for (size_t i = 0; i < size.size(); ++i)
    if (size[i] > 0 && (size[smallest] <= 0 || size[i] < size[smallest])) smallest = i;
  std::vector<std::string> out;
  for (size_t i = 0; i < size.size(); ++i) {
    const std::string name =
        "object \"" + objects[i].setup.name + "\" is " + fmt(size[i]) + " m across";
    const char* hint =
        ": is its mesh or asset in other units (e.g. millimetres)? Give the object a \"size\" (m) "
        "in the scene";
    if (size[smallest] > 0 && size[i] > kRatio * size[smallest])
      out.push_back(name + ", " + fmt(size[i] / size[smallest]) + " times the size of object \"" +
                    objects[smallest].setup.name + "\" (" + fmt(size[smallest]) + " m)" + hint);
    else if (span > 0 && size[i] > kRatio * span)
      out.push_back(name + ", " + fmt(size[i] / span) +
                    " times the distance spanned by the objects' positions (" + fmt(span) + " m)" +
                    hint);
  }
  return out;
}

std::string file_name_from(const std::string& name) {
  std::string out;
  for (const char c : name.substr(0, 100))
    out +=
        std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' ? c : '_';
  if (out.empty()) out = "_";
  if (out[0] == '.') out[0] = '_';
  return out;
}

void write_contact_spheres(World& world, size_t pair, int side, const std::filesystem::path& path,
                           const VtuOptions& options) {
  const auto [i, j] = world.plan().pairs[pair];
  const collision::CollisionResult& r = world.results()[pair];
  const collision::SphereTree& tree = world.objects()[side ? j : i].asset.spheres;
  std::vector<int> ids;
  std::vector<double> leaf;
  for (const auto* list : {&r.colliding, &r.untested})
    for (const collision::NodePair& np : *list) {
      ids.push_back(side ? np.b : np.a);
      leaf.push_back(list == &r.colliding ? 1.0 : 0.0);
    }
  const auto n = static_cast<Eigen::Index>(ids.size());
  SphereSet set{MatX3d(n, 3), Eigen::VectorXd(n)};
  PointDataArray level{"level", Eigen::MatrixXd(n, 1)};
  PointDataArray colliding{"colliding_leaf", Eigen::MatrixXd(n, 1)};
  for (Eigen::Index k = 0; k < n; ++k) {
    const collision::Sphere& sp = tree.spheres[ids[static_cast<size_t>(k)]];
    set.centers.row(k) << sp.x, sp.y, sp.z;
    set.radii[k] = sp.r;
    level.values(k, 0) = tree.level[ids[static_cast<size_t>(k)]];
    colliding.values(k, 0) = leaf[static_cast<size_t>(k)];
  }
  const PointDataArray arrays[] = {level, colliding};
  write_vtu_sphere_set(path, set, arrays, options);
}

std::string metrics_csv(const std::vector<FrameMetrics>& frames) {
  std::ostringstream csv;
  csv.precision(9);
  csv << "frame,time,wall,fem,links,sphere_update,collision,response,budget,pair_list,"
         "collision_list,tests,interrupted,completed_level,active_pairs,max_penetration,"
         "contact_force,cycles,substeps,min_step,energy,exact_contacts,rollback,reused,softened,"
         "limited,subdivided,deep_pairs,depth_ratio,obstacle_vertices,obstacle_depth,deadline,"
         "deadline_met,lateness,min_budget_queries,fem_over_deadline,capped_pairs,deep_steps,"
         "deep_step_energy,predicted\n";
  for (const FrameMetrics& m : frames)
    csv << m.frame << ',' << m.time << ',' << m.wall << ',' << m.times.fem << ',' << m.times.links
        << ',' << m.times.sphere_update << ',' << m.times.collision << ',' << m.times.response
        << ',' << m.budget << ',' << m.pair_list << ',' << m.collision_list << ',' << m.tests << ','
        << m.interrupted << ',' << m.completed_level << ',' << m.active_pairs << ','
        << m.max_penetration << ',' << m.contact_force << ',' << m.cycles << ',' << m.substeps
        << ',' << m.min_step << ',' << m.energy << ',' << m.exact_contacts << ',' << m.rollback
        << ',' << m.reused << ',' << m.softened << ',' << m.limited << ',' << m.subdivided << ','
        << m.deep_pairs << ',' << m.depth_ratio << ',' << m.obstacle_vertices << ','
        << m.obstacle_depth << ',' << m.deadline << ',' << m.deadline_met << ',' << m.lateness
        << ',' << m.min_budget_queries << ',' << m.fem_over_deadline << ',' << m.capped_pairs
        << ',' << m.deep_steps << ',' << m.deep_step_energy << ',' << m.predicted << '\n';
  return csv.str();
}

RealTimeSummary summarize_real_time(const std::vector<FrameMetrics>& frames) {
  RealTimeSummary s;
  for (const FrameMetrics& m : frames) {
    if (m.deadline_met < 0) continue;
    ++s.frames;
    s.met += m.deadline_met;
    s.worst_lateness = std::max(s.worst_lateness, m.lateness);
    s.fem_over += m.fem_over_deadline;
    s.min_budget_queries += m.min_budget_queries;
    s.interrupted += m.interrupted;
    s.untested += m.pair_list;
  }
  return s;
}

std::vector<std::string> describe_mass_scaling(const World& world) {
  std::vector<std::string> lines;
  for (const coupling::RuntimeObject& o : world.objects())
    if (o.sim && o.sim->model().mass_scaling().target_ratio > 0)
      lines.push_back("object \"" + o.setup.name + "\": " + o.sim->model().mass_scaling().to_string());
  return lines;
}

std::vector<FrameMetrics> run_scene(const Scene& scene_in, const RunOptions& opt) {
  if (opt.out_dir.empty()) throw ParameterError("run_scene: an output folder is required");
  Scene scene = scene_in;
  if (opt.frames >= 0) scene.frames = opt.frames;
  if (scene.frames < 1 || scene.frames > 100000000)  // as the scene file's "frames"
    throw ParameterError("run_scene: frames must be in [1, 100000000], got " +
                         std::to_string(scene.frames));
  if (opt.target_fps >= 0) scene.world.target_fps = opt.target_fps;
  std::filesystem::create_directories(opt.out_dir);
  // Remove a previous run's results first: nothing stale that looks complete.
  std::filesystem::remove(opt.out_dir / "frames.csv");
  std::filesystem::remove(opt.out_dir / "scene.json");
  std::filesystem::remove(opt.out_dir / "version.txt");
  std::string scene_text;  // read first: a missing scene file fails before the run
  if (!opt.scene_file.empty()) {
    std::ifstream in(opt.scene_file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in) throw InputError(opt.scene_file.string() + ": cannot read the scene file to copy it");
    scene_text = text.str();
  }
  const std::filesystem::path vtu_dir = opt.out_dir / "vtu";
  const std::filesystem::path vtu_tmp = opt.out_dir / "vtu.part";
  std::filesystem::remove_all(vtu_dir);
  std::filesystem::remove_all(vtu_tmp);

  World world = make_world(scene, opt.cache_dir, opt.tool_dir, opt.preprocess_limits);
  if (opt.log)
    for (const std::string& line : describe_mass_scaling(world)) std::fprintf(opt.log, "%s\n", line.c_str());
  const std::vector<std::string> file_names = object_file_names(world);
  const bool tty = opt.progress && isatty(fileno(stderr));
  std::vector<FrameMetrics> frames;
  frames.reserve(scene.frames);
  std::vector<PvdEntry> pvd;
  std::vector<MatX3d> before(world.objects().size());  // non-FEM objects' positions before a frame
  if (scene.output.vtu_every > 0) {
    std::filesystem::create_directories(vtu_tmp);
    write_trees(world, vtu_tmp, file_names);
  }
  const auto start = std::chrono::steady_clock::now();
  // Real-time mode: frame f is due at start + (f + 1) / target_fps. Collision
  // detection gets what is left of each frame (World::step); an early frame
  // waits for its deadline, so the rate is held, not exceeded.
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(scene.world.target_fps > 0 ? 1.0 / scene.world.target_fps : 0.0));
  auto deadline = start;
  std::string deadline_warning;  // FEM alone exceeds the deadline (said once)
  for (int f = 0; f < scene.frames; ++f) {
    deadline += period;
    const bool write_vtu =
        scene.output.vtu_every > 0 && (f % scene.output.vtu_every == 0 || f + 1 == scene.frames);
    if (write_vtu)
      for (size_t k = 0; k < before.size(); ++k)
        if (!world.objects()[k].sim) before[k] = world.objects()[k].positions;
    FrameMetrics m = world.step();
    if (!m.deadline_warning.empty()) {
      deadline_warning = m.deadline_warning;
      std::fprintf(stderr, "%swarning: %s\n", opt.progress && isatty(fileno(stderr)) ? "\n" : "",
                   deadline_warning.c_str());
    }
    if (write_vtu) {
      const auto t0 = std::chrono::steady_clock::now();
      write_frame_vtu(world, scene, f, vtu_tmp, file_names, before, pvd);
      m.times.output = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    if (m.deadline > 0 && m.times.output > 0) {  // the frame's output counts too
      const double w = m.wall + m.times.output;
      m.deadline_met = w <= m.deadline ? 1 : 0;
      m.lateness = std::max(0.0, w - m.deadline);
    }
    if (scene.world.target_fps > 0) {
      if (std::chrono::steady_clock::now() > deadline) {
        deadline = std::chrono::steady_clock::now();  // late: the next frame starts now
      } else {
        std::this_thread::sleep_until(deadline);
      }
    }
    frames.push_back(m);
    if (opt.progress && (tty ? true : (f + 1) % std::max(1, scene.frames / 10) == 0)) {
      const double el =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const int width = 30, done = (f + 1) * width / scene.frames;
      std::fprintf(stderr, "%s[%s%s] %d/%d frames, %s elapsed%s", tty ? "\r" : "",
                   std::string(done, '#').c_str(), std::string(width - done, '.').c_str(), f + 1,
                   scene.frames, format_duration(el).c_str(), tty ? "" : "\n");
    }
  }
  if (tty) std::fprintf(stderr, "\n");

  if (opt.log) {
    std::fprintf(opt.log, "%-13s %7s %8s %8s %8s %8s %8s %9s %9s %6s %6s %7s\n", "frames", "fps",
                 "fem%", "links%", "update%", "collide%", "respond%", "PAIRLIST", "COLLLIST",
                 "intr.", "reused", "cycles");
    const int ranges = std::max(1, std::min(opt.summary_ranges, scene.frames));
    for (int r = 0; r < ranges; ++r) {
      const int a = r * scene.frames / ranges, b = (r + 1) * scene.frames / ranges;
      coupling::StageTimes sum;
      double wall = 0, pl = 0, cl = 0;
      int intr = 0, reused = 0;
      double cycles = 0;
      for (int f = a; f < b; ++f) {
        const FrameMetrics& m = frames[f];
        wall += m.wall;
        sum.fem += m.times.fem;
        sum.links += m.times.links;
        sum.sphere_update += m.times.sphere_update;
        sum.collision += m.times.collision;
        sum.response += m.times.response;
        pl += m.pair_list;
        cl += m.collision_list;
        intr += m.interrupted;
        reused += m.reused;
        cycles += m.cycles;
      }
      const double n = b - a;
      char label[32];
      std::snprintf(label, sizeof label, "%d-%d", a, b - 1);
      std::fprintf(opt.log, "%-13s %7.1f %8.1f %8.1f %8.1f %8.1f %8.1f %9.1f %9.1f %6d %6d %7.1f\n",
                   label, n / wall, 100 * sum.fem / wall, 100 * sum.links / wall,
                   100 * sum.sphere_update / wall, 100 * sum.collision / wall,
                   100 * sum.response / wall, pl / n, cl / n, intr, reused, cycles / n);
    }
  }

  // Never silent: surfaces that went through each other deeper than the
  // spheres resolve (a contact too fast or a penalty too soft for the load).
  int deep_frames = 0, first_deep = -1;
  double deepest = 0;
  for (const FrameMetrics& m : frames)
    if (m.deep_pairs > 0) {
      ++deep_frames;
      if (first_deep < 0) first_deep = m.frame;
      deepest = std::max(deepest, m.depth_ratio);
    }
  if (deep_frames > 0)
    std::fprintf(opt.log ? opt.log : stderr,
                 "warning: %d frame(s) with a penetration deeper than the penetrating leaf "
                 "sphere's radius (first at frame %d, deepest %.2f radii; frames.csv columns "
                 "deep_pairs, depth_ratio): the objects partly passed through each other (penalty "
                 "too soft for the speed or load: raise collision.stiffness)\n",
                 deep_frames, first_deep, deepest);

  if (opt.log && scene.world.target_fps > 0) {
    const double el =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const RealTimeSummary rt = summarize_real_time(frames);
    std::fprintf(opt.log,
                 "real-time mode: target %.1f fps, held %.1f fps; %d of %d frames met their "
                 "deadline (%.1f%%), worst lateness %.2f ms; cut: %d queries at the minimum "
                 "budget, %d interrupted, %lld untested pairs left\n",
                 scene.world.target_fps, scene.frames / el, rt.met, rt.frames,
                 100.0 * rt.met / std::max(1, rt.frames), 1e3 * rt.worst_lateness,
                 rt.min_budget_queries, rt.interrupted, static_cast<long long>(rt.untested));
    if (!deadline_warning.empty())
      std::fprintf(opt.log, "real-time mode: %d frame(s) where FEM alone exceeded the deadline; %s\n",
                   rt.fem_over, deadline_warning.c_str());
  }
  if (scene.output.csv) write_file_atomically(opt.out_dir / "frames.csv", metrics_csv(frames));
  if (!opt.scene_file.empty()) write_file_atomically(opt.out_dir / "scene.json", scene_text);
  write_file_atomically(opt.out_dir / "version.txt",
                        std::string("icd ") + ICD_VERSION_STRING + "\nscene: " +
                            (opt.scene_file.empty() ? scene.name : opt.scene_file.string()) + "\n");
  if (scene.output.vtu_every > 0) {
    // One collection for the whole run: every part (coarse and dense meshes,
    // contact spheres of each pair side) at every written frame.
    write_pvd(vtu_tmp / "run.pvd", pvd);
    std::filesystem::rename(vtu_tmp, vtu_dir);
  }
  return frames;
}

}  // namespace icd::runner
