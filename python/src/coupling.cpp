// icd.AssetBundle (and preprocessing), icd.WorldObject / icd.WorldSettings,
// and icd.World: a simulation built from objects or from a scene file,
// stepped frame by frame, with positions, velocities and loads read and set,
// and an optional callback before each frame (a scripted or haptic probe).
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <icd/config.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/rigid_links.hpp>
#include <icd/coupling/world.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#ifdef ICD_PYTHON_WITH_PREPROCESS
#include <icd/mesh/pipeline/preprocess.hpp>
#endif

#include "bindings.hpp"
#include "experiments/runner/locations.hpp"
#include "experiments/runner/run.hpp"
#include "experiments/runner/scene.hpp"

namespace py = pybind11;

namespace icd::python {
namespace {

using coupling::World;

coupling::RuntimeObject& object_at(World& w, int i) {
  if (i < 0 || i >= static_cast<int>(w.objects().size()))
    throw ParameterError("World: no object " + std::to_string(i) + " (the world has " +
                         std::to_string(w.objects().size()) + ")");
  return w.objects()[static_cast<size_t>(i)];
}

void check_rows(const coupling::RuntimeObject& o, const MatX3d& X, const char* what) {
  if (X.rows() != o.rest.rows() || !X.allFinite())
    throw ParameterError("object \"" + o.setup.name + "\": " + what + " need " +
                         std::to_string(o.rest.rows()) + " finite rows (one per coarse node), got " +
                         std::to_string(X.rows()));
}

}  // namespace

void bind_coupling(py::module_& m) {
  py::class_<coupling::AssetBundle>(m, "AssetBundle",
                                    "One object's geometry: dense surface, coarse tets, rigid "
                                    "links, sphere tree with its coarse-node association.")
      .def(py::init<>())
      .def_readwrite("dense", &coupling::AssetBundle::dense)
      .def_readwrite("coarse", &coupling::AssetBundle::coarse)
      .def_readwrite("spheres", &coupling::AssetBundle::spheres)
      .def(
          "placed",
          [](const coupling::AssetBundle& b, double size, const Eigen::Vector3d& position,
             const Eigen::Vector3d& rotation_deg) {
            coupling::AssetBundle c = b;
            coupling::place_asset(c, {size, position, rotation_deg});
            return c;
          },
          py::arg("size") = 0.0, py::arg("position") = Eigen::Vector3d::Zero(),
          py::arg("rotation_deg") = Eigen::Vector3d::Zero(),
          "A copy scaled (longest side -> size; 0 keeps units), rotated (XYZ Euler, "
          "degrees) about its centre and moved to position.")
      .def(
          "with_octree_spheres",
          [](const coupling::AssetBundle& b, int depth) {
            coupling::AssetBundle c = b;
            coupling::build_octree_spheres(c, depth);
            return c;
          },
          py::arg("depth") = 3, "A copy with an octree sphere tree tied to the coarse nodes.")
      .def("__repr__", [](const coupling::AssetBundle& b) {
        return "<icd.AssetBundle dense " + std::to_string(b.dense.V.rows()) + " vertices, coarse " +
               std::to_string(b.coarse.T.rows()) + " tets, " +
               std::to_string(b.spheres.num_nodes()) + " spheres>";
      });
  m.def("read_asset_bundle", &coupling::read_asset_bundle, py::arg("folder"),
        "Loads and checks a bundle folder written by icd-preprocess.");
  m.def("write_asset_bundle", &coupling::write_asset_bundle, py::arg("folder"), py::arg("bundle"));
  m.def(
      "make_primitive",
      [](const std::string& type, double radius, const Eigen::Vector3d& extent, int subdivisions,
         int cells, int depth) {
        coupling::PrimitiveSpec p;
        p.type = type;
        p.radius = radius;
        p.extent = extent;
        p.subdivisions = subdivisions;
        p.cells = cells;
        if (type != "sphere" && type != "box")
          throw ParameterError("make_primitive: type must be \"sphere\" or \"box\", got \"" + type + "\"");
        return coupling::make_primitive_asset(p, depth);
      },
      py::arg("type") = "sphere", py::arg("radius") = 0.1,
      py::arg("extent") = Eigen::Vector3d(0.2, 0.2, 0.2), py::arg("subdivisions") = 3,
      py::arg("cells") = 4, py::arg("depth") = 3,
      "A generated object: icosphere or box surface over structured coarse tets, octree tree.");
#ifdef ICD_PYTHON_WITH_PREPROCESS
  m.def(
      "preprocess",
      [](const std::filesystem::path& input, const std::optional<std::filesystem::path>& folder,
         int coarse_tets, bool spheres) {
        mesh::PreprocessOptions o;
        o.tetrahedralize.target_tets = coarse_tets;
        if (!spheres) o.sphere_builder = mesh::SphereBuilder::none;
        const SurfaceMesh dense = read_surface_mesh(input);
        mesh::PreprocessResult r = mesh::preprocess(dense, o, {}, input.string());
        if (folder) coupling::write_asset_bundle(*folder, r.bundle);
        return r.bundle;
      },
      py::arg("input"), py::arg("folder") = py::none(), py::arg("coarse_tets") = 1500,
      py::arg("spheres") = true,
      "Raw surface -> bundle (repair, simplify, tetrahedralize, rigid links, medial-axis "
      "sphere tree); written to `folder` when given.");
#endif

  py::enum_<coupling::ObjectKind>(m, "ObjectKind")
      .value("Deformable", coupling::ObjectKind::Deformable)
      .value("Rigid", coupling::ObjectKind::Rigid)
      .value("Static", coupling::ObjectKind::Static);
  py::enum_<fem::MaterialModel>(m, "MaterialModel")
      .value("Linear", fem::MaterialModel::Linear)
      .value("Corotational", fem::MaterialModel::Corotational)
      .value("StVK", fem::MaterialModel::StVK)
      .value("StableNeoHookean", fem::MaterialModel::StableNeoHookean);
  py::enum_<fem::Integrator>(m, "Integrator")
      .value("RK4", fem::Integrator::RK4)
      .value("SymplecticEuler", fem::Integrator::SymplecticEuler)
      .value("BackwardEuler", fem::Integrator::BackwardEuler);

  py::class_<coupling::WorldObject>(m, "WorldObject", "An object to simulate: setup and geometry.")
      .def(py::init([](const std::string& name, const coupling::AssetBundle& bundle,
                       coupling::ObjectKind kind, const Eigen::Vector3d& velocity, double young,
                       double poisson, double density, fem::MaterialModel model,
                       fem::Integrator integrator, std::vector<int> fixed_nodes) {
             coupling::WorldObject o;
             o.setup.name = name;
             o.setup.kind = kind;
             o.setup.velocity = velocity;
             o.setup.material.young = young;
             o.setup.material.poisson = poisson;
             o.setup.material.density = density;
             o.setup.material.model = model;
             o.setup.integrator = integrator;
             o.setup.fixed_nodes = std::move(fixed_nodes);
             o.asset = bundle;
             return o;
           }),
           py::arg("name"), py::arg("bundle"), py::arg("kind") = coupling::ObjectKind::Deformable,
           py::arg("velocity") = Eigen::Vector3d::Zero(), py::arg("young") = fem::Material{}.young,
           py::arg("poisson") = fem::Material{}.poisson, py::arg("density") = fem::Material{}.density,
           py::arg("model") = fem::Material{}.model, py::arg("integrator") = fem::Integrator::RK4,
           py::arg("fixed_nodes") = std::vector<int>{})
      .def_property_readonly("name", [](const coupling::WorldObject& o) { return o.setup.name; })
      .def_readwrite("bundle", &coupling::WorldObject::asset);

  py::class_<coupling::CollisionSpec>(m, "CollisionSpec", "Collision detection and response settings.")
      .def(py::init<>())
      .def_readwrite("query", &coupling::CollisionSpec::query, "the request of every pair query")
      .def_readwrite("temporal_coherence", &coupling::CollisionSpec::temporal_coherence)
      .def_readwrite("layered", &coupling::CollisionSpec::layered)
      .def_readwrite("single_cycle_when_apart", &coupling::CollisionSpec::single_cycle_when_apart)
      .def_readwrite("midpoint", &coupling::CollisionSpec::midpoint)
      .def_readwrite("passive", &coupling::CollisionSpec::passive)
      .def_property(
          "stiffness", [](const coupling::CollisionSpec& c) { return c.contact.stiffness; },
          [](coupling::CollisionSpec& c, double k) { c.contact.stiffness = k; },
          "penalty stiffness, N/m");
  py::class_<coupling::WorldSettings>(m, "WorldSettings", "Scene-wide settings of a simulation.")
      .def(py::init<>())
      .def_readwrite("frame_rate", &coupling::WorldSettings::frame_rate)
      .def_readwrite("gravity", &coupling::WorldSettings::gravity)
      .def_readwrite("target_fps", &coupling::WorldSettings::target_fps)
      .def_readwrite("collision", &coupling::WorldSettings::collision)
      .def_readwrite("dense_meshes", &coupling::WorldSettings::dense_meshes);

  py::class_<coupling::FrameMetrics>(m, "FrameMetrics", "What one frame did.")
      .def_readonly("frame", &coupling::FrameMetrics::frame)
      .def_readonly("time", &coupling::FrameMetrics::time)
      .def_readonly("wall", &coupling::FrameMetrics::wall)
      .def_readonly("pair_list", &coupling::FrameMetrics::pair_list)
      .def_readonly("collision_list", &coupling::FrameMetrics::collision_list)
      .def_readonly("tests", &coupling::FrameMetrics::tests)
      .def_readonly("interrupted", &coupling::FrameMetrics::interrupted)
      .def_readonly("active_pairs", &coupling::FrameMetrics::active_pairs)
      .def_readonly("max_penetration", &coupling::FrameMetrics::max_penetration)
      .def_readonly("contact_force", &coupling::FrameMetrics::contact_force)
      .def_readonly("cycles", &coupling::FrameMetrics::cycles)
      .def_readonly("substeps", &coupling::FrameMetrics::substeps)
      .def_readonly("energy", &coupling::FrameMetrics::energy);

  py::class_<World>(m, "World", py::dynamic_attr(),
                    "A simulation: FEM, sphere-tree update, interruptible collision, penalty "
                    "response, rigid links (paper sections 3-4).")
      .def(py::init([](std::vector<coupling::WorldObject> objects, const coupling::WorldSettings& s) {
             return std::make_unique<World>(std::move(objects), s);
           }),
           py::arg("objects"), py::arg("settings") = coupling::WorldSettings{})
      .def_static(
          "from_scene",
          [](const std::filesystem::path& scene_file, const std::vector<std::string>& overrides,
             std::optional<std::filesystem::path> cache_dir) {
            const runner::Scene scene = runner::load_scene(scene_file, overrides);
            return std::make_unique<World>(runner::make_world(
                scene, cache_dir ? *cache_dir : runner::default_cache_dir(), ICD_TOOL_DIR));
          },
          py::arg("path"), py::arg("overrides") = std::vector<std::string>{},
          py::arg("cache_dir") = py::none(),
          "A World from a scene file. overrides: [\"key=value\", ...] as icd-run's --set; "
          "cache_dir: the asset cache (default: $ICD_CACHE_DIR, else as the programs: see "
          "experiments/runner/locations.hpp), where raw meshes are preprocessed into.")
      .def_property_readonly("num_objects", [](World& w) { return w.objects().size(); })
      .def_property_readonly("names",
                             [](World& w) {
                               std::vector<std::string> n;
                               for (const auto& o : w.objects()) n.push_back(o.setup.name);
                               return n;
                             })
      .def(
          "step",
          [](py::object self) {
            World& w = self.cast<World&>();
            if (py::hasattr(self, "_on_step") && !self.attr("_on_step").is_none())
              self.attr("_on_step")(self);
            return w.step();
          },
          "Advances one frame; calls the on_step callback first, if any.")
      .def(
          "on_step",
          [](py::object self, py::object callback) { self.attr("_on_step") = callback; },
          py::arg("callback"),
          "Registers callback(world), run before every frame (None removes it): a script or "
          "haptic device may set positions, velocities or loads there.")
      .def("positions", [](World& w, int i) { return MatX3d(object_at(w, i).positions); },
           py::arg("object"), "coarse node positions (#V x 3, a copy)")
      .def(
          "velocities",
          [](World& w, int i) {
            coupling::RuntimeObject& o = object_at(w, i);
            if (!o.sim) return MatX3d(MatX3d::Zero(o.rest.rows(), 3));
            return MatX3d(o.sim->velocities());
          },
          py::arg("object"))
      .def("node_masses", [](World& w, int i) { return Eigen::VectorXd(object_at(w, i).node_mass); },
           py::arg("object"), "lumped coarse node masses, kg (1e30 for objects without FEM)")
      .def(
          "set_positions",
          [](World& w, int i, const MatX3d& X) {
            coupling::RuntimeObject& o = object_at(w, i);
            check_rows(o, X, "positions");
            o.positions = X;
            if (o.sim) o.sim->set_positions(X);
          },
          py::arg("object"), py::arg("positions"))
      .def(
          "set_velocities",
          [](World& w, int i, const MatX3d& V) {
            coupling::RuntimeObject& o = object_at(w, i);
            check_rows(o, V, "velocities");
            if (!o.sim)
              throw ParameterError("object \"" + o.setup.name + "\" is not deformable: no velocities");
            o.sim->set_velocities(V);
          },
          py::arg("object"), py::arg("velocities"))
      .def("set_external_forces", &World::set_external_forces, py::arg("object"), py::arg("forces"),
           "Loads on the coarse nodes (N, #V x 3), held until changed; an empty array removes them.")
      .def(
          "dense_positions",
          [](World& w, int i) {
            coupling::RuntimeObject& o = object_at(w, i);
            MatX3d dense(o.asset.dense.V.rows(), 3);
            coupling::apply(o.asset.links, o.positions, dense);
            return dense;
          },
          py::arg("object"), "dense surface vertices through the rigid links (Eqs. 9-10)")
      .def(
          "result",
          [](World& w, int pair) {
            if (pair < 0 || pair >= static_cast<int>(w.results().size()))
              throw ParameterError("World: no collision pair " + std::to_string(pair));
            return w.results()[static_cast<size_t>(pair)];
          },
          py::arg("pair"), "the last query of a collision pair")
      .def_property_readonly("pairs", [](World& w) { return w.plan().pairs; });
}

}  // namespace icd::python
