#pragma once
// One registration function per library module (python/src/<module>.cpp).
#include <pybind11/pybind11.h>

namespace icd::python {
void bind_mesh(pybind11::module_& m);
void bind_collision(pybind11::module_& m);
void bind_coupling(pybind11::module_& m);
}  // namespace icd::python
