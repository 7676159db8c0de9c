#include "python/scene_handle.hpp"

#include "common/errors.hpp"
#include "python/bindings.hpp"

namespace mw::python {

namespace {
// How a dict scene is named in messages, where a file scene gives its path.
constexpr const char* kDictSource = "scene dict";
}  // namespace

SceneHandle SceneHandle::load(Origin origin, std::string file_or_text, std::vector<std::string> overrides) {
    SceneHandle h;
    h.origin = origin;
    h.file_or_text = std::move(file_or_text);
    h.overrides = std::move(overrides);
    switch (h.origin) {
        case Origin::kBuiltIn: h.scene = load_scene("", h.overrides); break;
        case Origin::kFile:
            // load_scene reads "" as the built-in scene; the CLI refuses an empty SCENE the same way.
            if (h.file_or_text.empty()) throw InputError("empty scene path");
            h.scene = load_scene(h.file_or_text, h.overrides);
            break;
        case Origin::kDict: h.scene = parse_scene_text(h.file_or_text, kDictSource, h.overrides); break;
    }
    return h;
}

SceneHandle SceneHandle::with_overrides(const std::vector<std::string>& more) const {
    std::vector<std::string> all = overrides;
    all.insert(all.end(), more.begin(), more.end());
    return load(origin, file_or_text, all);
}

std::vector<std::string> overrides_from_python(const py::handle& overrides) {
    std::vector<std::string> out;
    if (overrides.is_none()) return out;
    if (py::isinstance<py::str>(overrides)) return {overrides.cast<std::string>()};
    if (py::isinstance<py::dict>(overrides)) {
        for (const auto& [key, value] : overrides.cast<py::dict>()) {
            if (!py::isinstance<py::str>(key))
                throw py::type_error("overrides: a key must be a str such as \"fluid.spacing\"");
            const std::string k = key.cast<std::string>();
            out.push_back(k + "=" + to_json_text(value, "--set " + k));
        }
        return out;
    }
    if (py::isinstance<py::list>(overrides) || py::isinstance<py::tuple>(overrides)) {
        for (const py::handle item : overrides) {
            if (!py::isinstance<py::str>(item))
                throw py::type_error("overrides: each must be a \"key=value\" str, as --set takes it");
            out.push_back(item.cast<std::string>());
        }
        return out;
    }
    throw py::type_error("overrides: expected a \"key=value\" str, a list of them, or a dict {key: value}");
}

SceneHandle scene_from_python(const py::handle& source, const py::handle& overrides) {
    const std::vector<std::string> extra = overrides_from_python(overrides);
    if (source.is_none()) return SceneHandle::load(SceneHandle::Origin::kBuiltIn, "", extra);
    if (py::isinstance<SceneHandle>(source)) return source.cast<const SceneHandle&>().with_overrides(extra);
    if (py::isinstance<py::dict>(source))
        return SceneHandle::load(SceneHandle::Origin::kDict, to_json_text(source, kDictSource), extra);
    if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
        const py::object path = py::module_::import("os").attr("fspath")(source);
        if (!py::isinstance<py::str>(path)) throw py::type_error("scene: a path must be text, not bytes");
        return SceneHandle::load(SceneHandle::Origin::kFile, path.cast<std::string>(), extra);
    }
    throw py::type_error("scene: expected None (the built-in dam break), a path, a dict or a Scene");
}

}  // namespace mw::python
