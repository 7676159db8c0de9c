// meltwater.Scene: a scene loaded from a file, a dict or the built-in dam break, with overrides
// in the form of the CLI's --set, and the resolved scene back as a dict.
#include <pybind11/stl.h>

#include "apps/scene_builder.hpp"
#include "python/bindings.hpp"
#include "python/scene_handle.hpp"

namespace mw::python {

namespace {
const char* origin_name(SceneHandle::Origin origin) {
    switch (origin) {
        case SceneHandle::Origin::kBuiltIn: return "built-in";
        case SceneHandle::Origin::kFile: return "file";
        case SceneHandle::Origin::kDict: return "dict";
    }
    return "";
}

// The resolved scene: every key with its value, as `meltwater info --json` and summary.json give it.
py::object resolved_dict(const SceneHandle& h) {
    return from_json_text(h.scene.resolved.dump(-1, ' ', false, SceneJson::error_handler_t::replace));
}
}  // namespace

void bind_scene(py::module_& m) {
    py::class_<SceneHandle>(m, "Scene", R"(A scene, checked as `meltwater run` checks it.

Scene(source=None, overrides=None)

source: None for the built-in 3D dam break (scenes/dam_break.json); a path to a scene file (str
or os.PathLike); a dict in the same schema (`meltwater schema`, meltwater.schema()); or a Scene,
whose source and overrides are kept and `overrides` added after them.
overrides: what the CLI's --set takes: "key=value", a list of such texts, or a dict
{"key.path": value} (values as JSON: {"solver.dt_mode": "cfl", "fluid_blocks.0.max": [0.4, 0.8, 0.8]}).

Raises meltwater.InputError with the CLI's message for any problem.)")
        .def(py::init([](const py::object& source, const py::object& overrides) {
                 return scene_from_python(source, overrides);
             }),
             py::arg("source") = py::none(), py::arg("overrides") = py::none())
        .def(
            "with_overrides",
            [](const SceneHandle& h, const py::object& overrides) {
                return h.with_overrides(overrides_from_python(overrides));
            },
            py::arg("overrides"), "A new Scene: this one's source with these overrides after its own.")
        .def("to_dict", &resolved_dict,
             "The resolved scene as a dict: every key with its value, defaults filled in, overrides applied.\n"
             "Scene(scene.to_dict()) is the same scene.")
        .def_property_readonly("name", [](const SceneHandle& h) { return h.scene.name; })
        .def_property_readonly("description", [](const SceneHandle& h) { return h.scene.description; })
        .def_property_readonly("source", [](const SceneHandle& h) { return h.scene.source; },
                               "Where it came from as messages name it: the path, \"scene dict\" or "
                               "\"built-in default scene\".")
        .def_property_readonly("origin", [](const SceneHandle& h) { return origin_name(h.origin); },
                               "\"built-in\", \"file\" or \"dict\".")
        .def_property_readonly("overrides", [](const SceneHandle& h) { return h.overrides; },
                               "The overrides applied, as \"key=value\" texts in order.")
        .def_property_readonly("end_time", [](const SceneHandle& h) { return h.scene.end_time; },
                               "run.end_time, s: where Simulation.run() stops when given neither steps nor until.")
        .def_property_readonly("fps", [](const SceneHandle& h) { return h.scene.fps; },
                               "output.fps: the frames Simulation.run(frames=...) writes per simulated second.")
        .def_property_readonly("spacing", [](const SceneHandle& h) { return double(h.scene.params.fluid.spacing); },
                               "fluid.spacing r0, m.")
        .def_property_readonly("estimated_particles",
                               [](const SceneHandle& h) { return estimate_particle_count(h.scene); },
                               "The particles the fluid blocks, walls, static boxes and emitters will make "
                               "(objects, known once sampled, left out).")
        .def("__repr__", [](const SceneHandle& h) {
            return "<meltwater.Scene " + (h.scene.name.empty() ? std::string("(unnamed)") : h.scene.name) + " from " +
                   h.scene.source + (h.overrides.empty() ? "" : ", " + std::to_string(h.overrides.size()) + " overrides") +
                   ">";
        });
}

}  // namespace mw::python
