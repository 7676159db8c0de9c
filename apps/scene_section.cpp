#include "apps/scene_section.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace mw {

std::string format_scene_number(double v) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.10g", v);
    return buffer;
}

std::string json_type_name(const SceneJson& v) {
    if (v.is_null()) return "null";
    if (v.is_boolean()) return "a boolean";
    if (v.is_number_integer() || v.is_number_unsigned()) return "an integer";
    if (v.is_number()) return "a number";
    if (v.is_string()) return "a string \"" + v.get<std::string>() + "\"";
    if (v.is_array()) return "an array";
    return "an object";
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i)
        for (std::size_t j = 1; j <= b.size(); ++j) {
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1])});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}

namespace {

// Short keys allow one edit, longer ones two: "min" is not a misspelling of "max".
bool close_enough(const std::string& written, const std::string& meant) {
    return edit_distance(written, meant) <= (meant.size() >= 6 ? 2u : 1u);
}

// A key of `object` that looks like a misspelling of `wanted` (and is not a key read already), or "".
std::string misspelling_of(const std::string& wanted, const SceneJson* object, const std::vector<std::string>& known) {
    if (!object || !object->is_object()) return "";
    for (auto it = object->begin(); it != object->end(); ++it) {
        if (it.key() == wanted || std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
        if (close_enough(it.key(), wanted)) return it.key();
    }
    return "";
}

// A number the simulation's scalar type (Real) holds: in range after the conversion, and not so
// small that it would turn into zero or a subnormal (a time step of 1e-300, say).
bool representable(double v) {
    const double magnitude = std::fabs(v);
    return magnitude == 0 || (magnitude <= double(std::numeric_limits<Real>::max()) &&
                              magnitude >= double(std::numeric_limits<Real>::min()));
}
std::string representable_range() {
    return std::string("outside what the simulation's ") + (sizeof(Real) == 4 ? "float" : "double") +
           " numbers hold (magnitudes " + format_scene_number(double(std::numeric_limits<Real>::min())) + " to " +
           format_scene_number(double(std::numeric_limits<Real>::max())) + ", or 0)";
}

// JSON text must be UTF-8; nlohmann checks it when it writes a string (as summary.json will).
bool valid_utf8(const std::string& text) {
    try {
        (void)SceneJson(text).dump();
        return true;
    } catch (const SceneJson::type_error&) {
        return false;
    }
}

std::string join(const std::vector<std::string>& items) {
    std::string s;
    for (const auto& i : items) s += (s.empty() ? "" : ", ") + i;
    return s;
}

}  // namespace

Section::Section(const SceneJson* in, std::string path, std::string schema, SceneJson& out, const std::string& source,
                 ResolvedKeys& resolved)
    : in_(in), path_(std::move(path)), schema_(std::move(schema)), out_(out), source_(source), resolved_(resolved) {
    if (in_ && !in_->is_object()) fail(path_, "expected an object, got " + json_type_name(*in_));
    out_ = SceneJson::object();
}

void Section::fail(const std::string& key_path, const std::string& what) const {
    throw InputError(source_ + ": " + (key_path.empty() ? std::string("scene") : key_path) + ": " + what);
}

void Section::missing(const std::string& key) const {
    std::string hint = misspelling_hint(key);
    // A whole section absent: its misspelt name sits in the parent.
    if (hint.empty() && !in_ && parent_in_) {
        const std::string near = misspelling_of(name_in_parent_, parent_in_, {});
        if (!near.empty()) hint = " (there is no \"" + name_in_parent_ + "\"; is \"" + near + "\" a misspelling of it?)";
    }
    fail(key_path(key), "required key is missing" + hint);
}

std::string Section::misspelling_hint(const std::string& key) const {
    const std::string near = misspelling_of(key, in_, known_);
    return near.empty() ? "" : " (is \"" + near + "\" a misspelling of it?)";
}

const SceneJson* Section::find(const std::string& key) {
    known_.push_back(key);
    if (!in_) return nullptr;
    auto it = in_->find(key);
    return it == in_->end() ? nullptr : &*it;
}

Section Section::object(const std::string& key) {
    const SceneJson* v = find(key);
    const std::string schema = schema_.empty() ? key : schema_ + "." + key;
    Section child(v, key_path(key), schema, out_[key], source_, resolved_);
    child.parent_in_ = in_;
    child.name_in_parent_ = key;
    return child;
}

void Section::finish() const {
    if (!in_) return;
    for (auto it = in_->begin(); it != in_->end(); ++it) {
        if (std::find(known_.begin(), known_.end(), it.key()) != known_.end()) continue;
        // The closest known key, when the unknown one looks like a misspelling of it.
        std::string closest;
        std::size_t best = std::numeric_limits<std::size_t>::max();
        for (const std::string& k : known_) {
            const std::size_t d = edit_distance(it.key(), k);
            if (close_enough(it.key(), k) && d < best) best = d, closest = k;
        }
        fail(key_path(it.key()), "unknown key" + (closest.empty() ? "" : "; did you mean \"" + closest + "\"?") +
                                     " (allowed here: " + join(known_) + ")");
    }
}

double Section::to_number(const SceneJson& v, const std::string& key_path) const {
    if (!v.is_number()) fail(key_path, "expected a number, got " + json_type_name(v));
    return v.get<double>();
}

ParamValue Section::convert(const SceneJson& v, const std::string& key, ParamType type,
                            const std::vector<std::string>& choices) const {
    const std::string p = key_path(key);
    switch (type) {
        case ParamType::kOptionalNumber:
            if (v.is_null()) return ParamValue::null();
            return ParamValue::of(to_number(v, p));
        case ParamType::kNumber: return ParamValue::of(to_number(v, p));
        case ParamType::kInteger: {
            const double d = to_number(v, p);
            if (d != std::floor(d)) fail(p, "expected an integer, got " + format_scene_number(d));
            return ParamValue::of(d);
        }
        case ParamType::kBoolean:
            if (!v.is_boolean()) fail(p, "expected true or false, got " + json_type_name(v));
            return ParamValue::of_bool(v.get<bool>());
        case ParamType::kText:
            if (!v.is_string()) fail(p, "expected a string, got " + json_type_name(v));
            // A Latin-1 byte (a --set value that is not JSON is taken as plain text) would
            // otherwise only fail when summary.json is written, after the run.
            if (!valid_utf8(v.get<std::string>())) fail(p, "the text is not valid UTF-8");
            return ParamValue::of(v.get<std::string>());
        case ParamType::kChoice: {
            if (!v.is_string()) fail(p, "expected one of " + join(choices) + ", got " + json_type_name(v));
            const std::string text = v.get<std::string>();
            if (std::find(choices.begin(), choices.end(), text) == choices.end())
                fail(p, "expected one of " + join(choices) + ", got \"" + text + "\"");
            return ParamValue::of(text);
        }
        case ParamType::kVector: {
            // A 2D scene's vectors are [x, y] (z = 0), or [x, y, z] as its resolved scene writes
            // them: the preview's camera stands off the plane (check_plane() refuses z elsewhere).
            const bool flat = resolved_.dimensions == 2;
            const bool sized = v.is_array() && (v.size() == 3 || (flat && v.size() == 2));
            if (!sized)
                fail(p, std::string(flat ? "expected an array of 2 numbers [x, y] (the scene is 2D)"
                                         : "expected an array of 3 numbers [x, y, z]") +
                            ", got " + (v.is_array() ? "an array of " + std::to_string(v.size()) : json_type_name(v)));
            ParamValue value = ParamValue::of(Vec3{0, 0, 0});
            for (std::size_t a = 0; a < v.size(); ++a)
                value.vector[a] = to_number(v[a], p + "[" + std::to_string(a) + "]");
            return value;
        }
        case ParamType::kTextList: {
            if (!v.is_array()) fail(p, "expected an array of strings, got " + json_type_name(v));
            std::vector<std::string> list;
            for (std::size_t i = 0; i < v.size(); ++i) {
                const std::string element = p + "[" + std::to_string(i) + "]";
                const SceneJson& e = v[i];
                if (!e.is_string()) fail(element, "expected one of " + join(choices) + ", got " + json_type_name(e));
                if (std::find(choices.begin(), choices.end(), e.get<std::string>()) == choices.end())
                    fail(element, "expected one of " + join(choices) + ", got \"" + e.get<std::string>() + "\"");
                list.push_back(e.get<std::string>());
            }
            return ParamValue::of(list);
        }
    }
    return ParamValue::null();
}

void Section::check_number(const std::string& key_path, double value, const ParamRange& range) const {
    if (!range.contains(value)) fail(key_path, "must be " + range.describe() + ", got " + format_scene_number(value));
    if (!representable(value)) fail(key_path, format_scene_number(value) + " is " + representable_range());
}

void Section::check(const std::string& key, const ParamValue& value, ParamType type, const ParamRange& range, int lo,
                    int hi) const {
    const std::string p = key_path(key);
    if (type == ParamType::kNumber || (type == ParamType::kOptionalNumber && value.kind == ParamValue::Kind::kNumber))
        check_number(p, value.number, range);
    if (type == ParamType::kInteger && (value.number < lo || value.number > hi))
        fail(p, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                    format_scene_number(value.number));
    if (type == ParamType::kVector)
        for (int a = 0; a < 3; ++a) check_number(p + "[" + std::to_string(a) + "]", value.vector[a], range);
}

SceneJson Section::to_json(const ParamValue& value, ParamType type) {
    switch (value.kind) {
        case ParamValue::Kind::kNull: return nullptr;
        case ParamValue::Kind::kNumber:
            return type == ParamType::kInteger ? SceneJson(static_cast<int>(value.number)) : SceneJson(value.number);
        case ParamValue::Kind::kBoolean: return value.boolean;
        case ParamValue::Kind::kText: return value.text;
        case ParamValue::Kind::kVector: return SceneJson::array({value.vector[0], value.vector[1], value.vector[2]});
        case ParamValue::Kind::kTextList: return value.list;
    }
    return nullptr;
}

}  // namespace mw
