// Scene JSON as text (apps/scene_json.cpp): parsing, `--set` overrides, reading a scene file.
#pragma once
#include <string>

#include "apps/scene.hpp"

namespace mw {

// JSON text parsed as nlohmann does, except that a key given twice in one object is refused,
// naming the key and where it is. Parse errors are nlohmann's exceptions; `source` prefixes the
// message.
SceneJson parse_json_refusing_duplicates(const std::string& text, const std::string& source);

// Applies one override ("key.path=value") to `raw`, after checking that its path names a key of
// the resolved scene. Throws InputError naming the override.
void apply_override(SceneJson& raw, const SceneJson& resolved, const std::string& option);

// A scene file's text (at most 64 MiB). Throws InputError naming the file.
std::string read_scene_file(const std::string& path);

}  // namespace mw
