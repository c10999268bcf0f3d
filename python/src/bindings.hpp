// Shared declarations of the Python module's C++ files (python/src/, docs/python.md).
#pragma once

#include <pybind11/pybind11.h>

namespace cairn::python {

namespace py = pybind11;

/// Input: loading from files and dicts, InputError for Python, cairn.keys() (input.cpp).
void bind_input(py::module_& m);
/// The engine and its run control (engine.cpp).
void bind_engine(py::module_& m);

}  // namespace cairn::python
