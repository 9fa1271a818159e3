// icd.SphereTree, .sph files, octree trees, and the interruptible collision
// query (icd.CollisionRequest -> icd.collide -> icd.CollisionResult).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <icd/collision/octree_tree.hpp>
#include <icd/collision/sph_io.hpp>
#include <icd/collision/sphere_tree.hpp>
#include <icd/collision/traversal.hpp>

#include "bindings.hpp"

namespace py = pybind11;

namespace icd::python {
namespace {

using collision::CollisionRequest;
using collision::CollisionResult;
using collision::NodePair;
using collision::SphereTree;

// Spheres as an (n, 4) array: x, y, z, r (a copy).
py::array_t<double> sphere_array(const std::vector<collision::Sphere>& s) {
  py::array_t<double> a({static_cast<py::ssize_t>(s.size()), py::ssize_t{4}});
  auto v = a.mutable_unchecked<2>();
  for (size_t i = 0; i < s.size(); ++i) {
    const auto k = static_cast<py::ssize_t>(i);
    v(k, 0) = s[i].x;
    v(k, 1) = s[i].y;
    v(k, 2) = s[i].z;
    v(k, 3) = s[i].r;
  }
  return a;
}

// Node pairs as a (k, 2) int32 array of (node of a, node of b).
py::array_t<int32_t> pair_array(const std::vector<NodePair>& p) {
  py::array_t<int32_t> a({static_cast<py::ssize_t>(p.size()), py::ssize_t{2}});
  auto v = a.mutable_unchecked<2>();
  for (size_t i = 0; i < p.size(); ++i) {
    v(static_cast<py::ssize_t>(i), 0) = p[i].a;
    v(static_cast<py::ssize_t>(i), 1) = p[i].b;
  }
  return a;
}

template <class T>
py::array_t<T> vector_array(const std::vector<T>& v) {
  return py::array_t<T>(static_cast<py::ssize_t>(v.size()), v.data());
}

}  // namespace

void bind_collision(py::module_& m) {
  py::class_<SphereTree>(m, "SphereTree", "A sphere tree in breadth-first order; node 0 is the root.")
      .def(py::init<>())
      .def_property_readonly("num_nodes", &SphereTree::num_nodes)
      .def_property_readonly("num_levels", &SphereTree::num_levels)
      .def_property_readonly("spheres", [](const SphereTree& t) { return sphere_array(t.spheres); },
                             "current spheres, (n, 4): x, y, z, r")
      .def_property_readonly("rest_spheres",
                             [](const SphereTree& t) { return sphere_array(t.rest_spheres); })
      .def_property_readonly("level", [](const SphereTree& t) { return vector_array(t.level); })
      .def_property_readonly("first_child",
                             [](const SphereTree& t) { return vector_array(t.first_child); })
      .def_property_readonly("child_count",
                             [](const SphereTree& t) { return vector_array(t.child_count); })
      .def("validate", [](const SphereTree& t) { collision::validate(t); },
           "Raises icd.ParameterError when an invariant does not hold.")
      .def("__repr__", [](const SphereTree& t) {
        return "<icd.SphereTree " + std::to_string(t.num_nodes()) + " spheres, " +
               std::to_string(t.num_levels()) + " levels>";
      });
  m.def("read_sph", [](const std::string& path) { return collision::read_sph(path); },
        py::arg("path"), "Reads a sphere tree in the .sph format.");
  m.def("write_sph", [](const std::string& path, const SphereTree& t) { collision::write_sph(path, t); },
        py::arg("path"), py::arg("tree"), "Writes a sphere tree in the .sph format.");
  m.def(
      "build_octree_tree",
      [](const MatX3d& V, const MatX3i& F, int levels) {
        collision::OctreeTreeOptions o;
        o.levels = levels;
        return collision::build_octree_tree(V, F, o);
      },
      py::arg("V"), py::arg("F"), py::arg("levels") = 4,
      "An octree sphere tree covering the surface (levels counting the root).");

  py::enum_<collision::TraversalMode>(m, "TraversalMode")
      .value("BreadthFirstFifo", collision::TraversalMode::BreadthFirstFifo)
      .value("BreadthFirstLiteral", collision::TraversalMode::BreadthFirstLiteral)
      .value("DepthFirst", collision::TraversalMode::DepthFirst)
      .value("DepthFirstLiteral", collision::TraversalMode::DepthFirstLiteral)
      .value("Priority", collision::TraversalMode::Priority);
  py::enum_<collision::StopReason>(m, "StopReason")
      .value("Completed", collision::StopReason::Completed)
      .value("TimeBudget", collision::StopReason::TimeBudget)
      .value("TestBudget", collision::StopReason::TestBudget);

  py::class_<CollisionRequest>(m, "CollisionRequest",
                               "What a query does and how long it may try (paper Fig. 7).")
      .def(py::init<>())
      .def(py::init([](double budget_seconds, int64_t budget_tests, collision::TraversalMode mode) {
             CollisionRequest r;
             r.budget_seconds = budget_seconds;
             r.budget_tests = budget_tests;
             r.mode = mode;
             return r;
           }),
           py::arg("budget_seconds") = std::numeric_limits<double>::infinity(),
           py::arg("budget_tests") = -1, py::arg("mode") = collision::TraversalMode::BreadthFirstFifo)
      .def_readwrite("budget_seconds", &CollisionRequest::budget_seconds)
      .def_readwrite("budget_tests", &CollisionRequest::budget_tests)
      .def_readwrite("mode", &CollisionRequest::mode)
      .def_readwrite("parent_filter", &CollisionRequest::parent_filter)
      .def_readwrite("clock_check_interval", &CollisionRequest::clock_check_interval)
      .def_readwrite("depth_cap", &CollisionRequest::depth_cap)
      .def_readwrite("max_list_size", &CollisionRequest::max_list_size)
      .def_static("paper_reference", &CollisionRequest::paper_reference, py::arg("budget_seconds"));

  py::class_<CollisionResult>(m, "CollisionResult", "What a query found, and why it stopped.")
      .def_property_readonly("colliding", [](const CollisionResult& r) { return pair_array(r.colliding); },
                             "COLLISIONLIST: overlapping leaf pairs, (k, 2) node indices")
      .def_property_readonly("untested", [](const CollisionResult& r) { return pair_array(r.untested); },
                             "PAIRLIST at the interruption: pairs assumed colliding, (k, 2)")
      .def_readonly("interrupted", &CollisionResult::interrupted)
      .def_readonly("stop_reason", &CollisionResult::stop_reason)
      .def_readonly("tests", &CollisionResult::tests)
      .def_readonly("seconds", &CollisionResult::seconds)
      .def_readonly("completed_level", &CollisionResult::completed_level)
      .def("__repr__", [](const CollisionResult& r) {
        return "<icd.CollisionResult " + std::to_string(r.colliding.size()) + " colliding, " +
               std::to_string(r.untested.size()) + " untested, " + std::to_string(r.tests) +
               " tests" + (r.interrupted ? ", interrupted>" : ">");
      });
  m.def(
      "collide",
      [](const SphereTree& a, const SphereTree& b, const CollisionRequest& request) {
        return collision::collide(a, b, request);
      },
      py::arg("a"), py::arg("b"), py::arg("request") = CollisionRequest{},
      "Collides the current spheres of two trees under the request's budget.");
}

}  // namespace icd::python
