// The Python module `meltwater` (docs/python.md): scenes, simulations on either backend, their
// particles as NumPy arrays, frames; the program's errors as Python exceptions whose messages are
// the lines `meltwater` prints.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "algorithms/particle_types.hpp"
#include "apps/scene.hpp"
#include "common/errors.hpp"
#include "python/bindings.hpp"
#include "simulation/factory.hpp"

namespace py = pybind11;

namespace {

void bind_errors(py::module_& m) {
    // Bad input is a ValueError to Python; a device that cannot and a simulation that failed are
    // RuntimeErrors. The message is what() alone, the line the CLI prints after its prefix.
    py::register_exception<mw::InputError>(m, "InputError", PyExc_ValueError);
    py::register_exception<mw::DeviceError>(m, "DeviceError", PyExc_RuntimeError);
    py::register_exception<mw::SimulationError>(m, "SimulationError", PyExc_RuntimeError);
}

py::dict backend_dict(const mw::BackendInfo& b) {
    py::dict d;
    d["compiled"] = b.compiled;
    d["available"] = b.available;
    d["description"] = b.description;
    return d;
}

py::list schema_list() {
    py::list rows;
    for (const mw::ParamDoc& p : mw::scene_schema()) {
        py::dict row;
        row["key"] = p.path;
        row["type"] = p.type;
        row["default"] = p.default_text;
        row["allowed"] = p.allowed;
        row["unit"] = p.unit;
        row["doc"] = p.doc;
        rows.append(row);
    }
    return rows;
}

void bind_particle_types(py::module_& m) {
    m.attr("FLUID") = int(mw::kFluid);
    m.attr("STATIC_BOUNDARY") = int(mw::kStaticBoundary);
    m.attr("SURFACE_BOUNDARY") = int(mw::kSurfaceBoundary);
    m.attr("INNER_BOUNDARY") = int(mw::kInnerBoundary);
    m.attr("GEOMETRY") = int(mw::kGeometry);
    m.attr("PENDING") = int(mw::kPending);
}

}  // namespace

PYBIND11_MODULE(meltwater, m) {
    m.doc() = "Meltwater: SPH fluid and solids (docs/python.md). Scene, Simulation, and the errors "
              "InputError, DeviceError, SimulationError.";
    m.attr("__version__") = MW_VERSION;
#ifdef MW_DOUBLE
    m.attr("REAL") = "float64";
#else
    m.attr("REAL") = "float32";
#endif
    bind_errors(m);
    bind_particle_types(m);
    mw::python::bind_scene(m);
    mw::python::bind_simulation(m);
    m.def(
        "backends",
        []() {
            py::dict d;
            d["openmp"] = backend_dict(mw::openmp_backend_info());
            d["cuda"] = backend_dict(mw::cuda_backend_info());
            return d;
        },
        "Each backend: compiled in, usable now, and its device (or why not), as `meltwater backends` says.");
    m.def("schema", &schema_list,
          "Every scene key: key, type, default, allowed, unit, doc, as `meltwater schema` lists them.");
}
