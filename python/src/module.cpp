// The `icd` Python module: meshes, sphere trees and collision queries, asset
// bundles and preprocessing, and simulations (World). C++ errors become
// icd.InputError (bad input: files, fields) and icd.ParameterError (bad
// arguments), both ValueError, with the same messages.
#include <pybind11/pybind11.h>

#include <icd/config.hpp>
#include <icd/mesh/core/error.hpp>

#include "bindings.hpp"

PYBIND11_MODULE(icd, m) {
  m.doc() = "icd: interruptible collision detection for deformable objects";
  m.attr("__version__") = ICD_VERSION_STRING;
  pybind11::register_exception<icd::InputError>(m, "InputError", PyExc_ValueError);
  pybind11::register_exception<icd::ParameterError>(m, "ParameterError", PyExc_ValueError);
  icd::python::bind_mesh(m);
  icd::python::bind_collision(m);
  icd::python::bind_coupling(m);
}
