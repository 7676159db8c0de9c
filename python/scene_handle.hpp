// A scene as the Python module holds it: the resolved Scene, and where it came from, so that more
// overrides load it again from there and go through the checks `meltwater run SCENE --set ...`
// makes (overrides apply to the scene as written, not to the resolved one).
#pragma once
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "apps/scene.hpp"

namespace mw::python {
namespace py = pybind11;

struct SceneHandle {
    enum class Origin { kBuiltIn, kFile, kDict };
    Origin origin = Origin::kBuiltIn;
    std::string file_or_text;            // kFile: the path; kDict: the dict as JSON text
    std::vector<std::string> overrides;  // "key=value", in the order they apply
    Scene scene;

    // Reads the scene with `overrides` (load_scene, parse_scene_text); InputError as the CLI's.
    static SceneHandle load(Origin origin, std::string file_or_text, std::vector<std::string> overrides);
    SceneHandle with_overrides(const std::vector<std::string>& more) const;
};

// The source of a scene: None (the built-in dam break), a path (str or os.PathLike), a dict in the
// schema of scenes/*.json, or a Scene (its source and overrides, to which `overrides` are added).
SceneHandle scene_from_python(const py::handle& source, const py::handle& overrides);

// Overrides as Python gives them, as the CLI's "key=value" texts: None, one "key=value" text, a
// list or tuple of them, or a dict {key: value} whose values are written as JSON (so that
// {"solver.dt_mode": "cfl"} is the string and {"fluid.spacing": 0.04} the number).
std::vector<std::string> overrides_from_python(const py::handle& overrides);

}  // namespace mw::python
