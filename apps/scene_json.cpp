// Scene JSON as text: parsing that refuses a key given twice, `--set` overrides applied to the
// raw scene, and reading a scene file with a size limit.
#include "apps/scene_json.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_set>

#include "common/errors.hpp"

namespace mw {

namespace {

// "fluid_blocks[0].min" and "fluid_blocks.0.min" both give {fluid_blocks, 0, min}.
std::vector<std::string> split_key_path(const std::string& key, const std::string& option) {
    // a.b[2].c and a.b.2.c name the same key; a bracket must hold a bare index and close at once.
    std::string normalised;
    for (std::size_t i = 0; i < key.size(); ++i) {
        if (key[i] == ']') throw InputError("--set " + option + ": malformed key path '" + key + "' (a stray ']')");
        if (key[i] != '[') {
            normalised += key[i];
            continue;
        }
        const std::size_t close = key.find(']', i);
        const std::string index = close == std::string::npos ? "" : key.substr(i + 1, close - i - 1);
        if (index.empty() || index.find_first_not_of("0123456789") != std::string::npos ||
            (close + 1 < key.size() && key[close + 1] != '.' && key[close + 1] != '['))
            throw InputError("--set " + option + ": malformed key path '" + key + "' (write [N] with an index N)");
        normalised += '.' + index;
        i = close;
    }
    std::vector<std::string> parts;
    std::stringstream ss(normalised);
    std::string part;
    while (std::getline(ss, part, '.')) {
        if (part.empty()) throw InputError("--set " + option + ": malformed key path '" + key + "'");
        parts.push_back(part);
    }
    if (parts.empty() || normalised.back() == '.') throw InputError("--set " + option + ": malformed key path '" + key + "'");
    return parts;
}

bool is_index(const std::string& s) {
    return !s.empty() && s.size() < 9 && s.find_first_not_of("0123456789") == std::string::npos;
}

std::string list_keys(const SceneJson& obj) {
    std::string s;
    for (auto it = obj.begin(); it != obj.end(); ++it) s += (s.empty() ? "" : ", ") + it.key();
    return s;
}

}  // namespace

// JSON text parsed as nlohmann does, except that a key given twice in one object is refused,
// naming the key and where it is (nlohmann keeps the last; in a scene that is almost always an
// edit gone wrong). Parse errors are nlohmann's exceptions; `source` prefixes the message.
SceneJson parse_json_refusing_duplicates(const std::string& text, const std::string& source) {
    struct Container {
        bool is_array;
        std::string name;                    // its key in the parent object, "[]" in an array, "" at the top
        std::unordered_set<std::string> keys;  // a set: a file of 100k keys must not take minutes
    };
    std::vector<Container> open;
    std::string last_key;
    auto refuse_duplicates = [&](int /*depth*/, SceneJson::parse_event_t event, SceneJson& parsed) {
        using Event = SceneJson::parse_event_t;
        if (event == Event::object_start || event == Event::array_start) {
            const std::string name = open.empty() ? "" : open.back().is_array ? "[]" : last_key;
            open.push_back({event == Event::array_start, name, {}});
        } else if (event == Event::object_end || event == Event::array_end) {
            open.pop_back();
        } else if (event == Event::key) {
            last_key = parsed.get<std::string>();
            if (!open.back().keys.insert(last_key).second) {
                std::string path;
                for (std::size_t k = 1; k < open.size(); ++k)
                    path += (open[k].name == "[]" || path.empty() ? "" : ".") + open[k].name;
                path += (path.empty() ? "" : ".") + last_key;
                throw InputError(source + ": " + path + ": the key appears twice in its object");
            }
        }
        return true;
    };
    return SceneJson::parse(text, refuse_duplicates);
}

// Applies one override to `raw`, after checking that its path names a key of the resolved scene.
void apply_override(SceneJson& raw, const SceneJson& resolved, const std::string& option) {
    const auto eq = option.find('=');
    if (eq == std::string::npos || eq == 0)
        throw InputError("--set " + option + ": expected KEY=VALUE, for example --set solver.dt=0.002");
    const std::string key = option.substr(0, eq), text = option.substr(eq + 1);
    const std::vector<std::string> parts = split_key_path(key, option);

    // The path must exist in the resolved scene (which has every key of the schema).
    const SceneJson* r = &resolved;
    std::string walked;
    for (const auto& p : parts) {
        if (r->is_object()) {
            auto it = r->find(p);
            if (it == r->end())
                throw InputError("--set " + key + ": no such key in the scene" +
                                 (walked.empty() ? ""
                                  : r->empty() ? " (" + walked + " has no keys until it is set; set it whole, e.g. --set '" +
                                                     walked + "={...}')"
                                               : " (" + walked + " has: " + list_keys(*r) + ")") +
                                 (walked.empty() ? " (top-level keys: " + list_keys(*r) + ")" : ""));
            r = &*it;
        } else if (r->is_array()) {
            if (!is_index(p) || std::stoul(p) >= r->size())
                throw InputError("--set " + key + ": " + walked + " has " + std::to_string(r->size()) +
                                 " elements; '" + p + "' is not an index of it");
            r = &(*r)[std::stoul(p)];
        } else {
            throw InputError("--set " + key + ": " + walked + " is a value, not a section");
        }
        walked += (walked.empty() ? "" : ".") + p;
    }

    SceneJson value;
    try {
        value = parse_json_refusing_duplicates(text, "--set " + key);
    } catch (const SceneJson::parse_error&) {
        value = text;  // not JSON: a plain string (e.g. --set solver.dt_mode=cfl)
    } catch (const SceneJson::exception&) {
        throw InputError("--set " + key + ": '" + text + "' is not a representable number");
    }

    // Walk the raw scene along the same path, creating the sections it leaves out. An earlier
    // --set may have replaced a section of the raw scene by a value: that is named, not followed.
    SceneJson* node = &raw;
    const SceneJson* res = &resolved;  // the same place in the resolved scene, while it has one
    std::string here;
    for (std::size_t i = 0; i < parts.size(); ++i) {
        const std::string& p = parts[i];
        const bool last = i + 1 == parts.size();
        if (node->is_array()) {
            if (!is_index(p) || std::stoul(p) >= node->size())
                throw InputError("--set " + key + ": no element " + p + " in " + here + " of the scene");
            const std::size_t idx = std::stoul(p);
            res = res && res->is_array() && idx < res->size() ? &(*res)[idx] : nullptr;
            if (last) (*node)[idx] = value;
            else node = &(*node)[idx];
        } else if (node->is_object()) {
            const auto found = res && res->is_object() ? res->find(p) : SceneJson::const_iterator{};
            res = res && res->is_object() && found != res->end() ? &*found : nullptr;
            if (last) (*node)[p] = value;
            else {
                if (!node->contains(p)) (*node)[p] = res && res->is_array() ? *res : SceneJson::object();
                node = &(*node)[p];
            }
        } else {
            throw InputError("--set " + key + ": " + here + " is a value in the scene (set by an earlier --set?), "
                             "not a section");
        }
        here += (here.empty() ? "" : ".") + p;
    }
}

std::string read_scene_file(const std::string& path) {
    std::error_code error;
    if (std::filesystem::is_directory(path, error)) throw InputError("scene file '" + path + "' is a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError("cannot open scene file '" + path + "': " + std::strerror(errno));
    // A scene is a few kilobytes; reading stops well past that (a device such as /dev/zero, or a
    // mesh given by mistake, would otherwise be read until memory runs out).
    constexpr std::size_t kMaxSceneBytes = 64u << 20;
    std::string text;
    char buffer[1 << 16];
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
        text.append(buffer, static_cast<std::size_t>(in.gcount()));
        if (text.size() > kMaxSceneBytes)
            throw InputError("scene file '" + path + "' is larger than 64 MiB: not a scene");
    }
    if (in.bad()) throw InputError("cannot read scene file '" + path + "'");
    return text;
}


}  // namespace mw
