// The parts of the `meltwater` Python module (module.cpp puts them together), and the bridge
// between Python values and the scenes' JSON that they share.
#pragma once
#include <string>

#include <pybind11/pybind11.h>

namespace mw::python {
namespace py = pybind11;

// A Python value as JSON text, through the json module. NumPy scalars and arrays stand for their
// plain values (a scene dict written with NumPy numbers reads as one written with floats). A value
// JSON cannot hold (NaN, an object) throws InputError: "`what`: why".
std::string to_json_text(const py::handle& value, const std::string& what);
// JSON text as Python values; objects become dicts in the order of their keys.
py::object from_json_text(const std::string& text);

void bind_scene(py::module_& m);       // scene_binding.cpp
void bind_simulation(py::module_& m);  // simulation_binding.cpp
}  // namespace mw::python
