// icd.SurfaceMesh, icd.TetMesh, reading and writing surface meshes.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/core/types.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/surface_writer.hpp>

#include "bindings.hpp"

namespace py = pybind11;

namespace icd::python {

void bind_mesh(py::module_& m) {
  py::class_<SurfaceMesh>(m, "SurfaceMesh", "A triangle surface: V (#V x 3 float64), F (#F x 3 int32).")
      .def(py::init<>())
      .def(py::init([](const MatX3d& V, const MatX3i& F) { return SurfaceMesh{V, F}; }),
           py::arg("V"), py::arg("F"))
      .def_readwrite("V", &SurfaceMesh::V)
      .def_readwrite("F", &SurfaceMesh::F)
      .def("__repr__", [](const SurfaceMesh& s) {
        return "<icd.SurfaceMesh " + std::to_string(s.V.rows()) + " vertices, " +
               std::to_string(s.F.rows()) + " faces>";
      });
  py::class_<TetMesh>(m, "TetMesh",
                      "A tet mesh: V (#V x 3), T (#T x 4, positive volume), F (boundary, #F x 3).")
      .def(py::init<>())
      .def_readwrite("V", &TetMesh::V)
      .def_readwrite("T", &TetMesh::T)
      .def_readwrite("F", &TetMesh::F)
      .def("__repr__", [](const TetMesh& t) {
        return "<icd.TetMesh " + std::to_string(t.V.rows()) + " vertices, " +
               std::to_string(t.T.rows()) + " tets>";
      });
  m.def("read_surface_mesh", [](const std::filesystem::path& p) { return read_surface_mesh(p); },
        py::arg("path"), "Reads an OFF, OBJ, PLY or STL surface; raises icd.InputError naming the file.");
  m.def("write_surface_mesh", &write_surface_mesh, py::arg("path"), py::arg("mesh"),
        "Writes a surface as OFF or OBJ (by the extension), atomically.");
  m.def("make_icosphere", &make_icosphere, py::arg("subdivisions"), py::arg("radius") = 1.0,
        "An icosphere surface (subdivisions of the icosahedron, radius).");
}

}  // namespace icd::python
