// One JSON object of a scene being read, against tables of keys (simulation/parameters.hpp).
// Each key read is validated (type, range, the simulation's number type), recorded with its
// resolved value in the output object, and marked as known; finish() refuses every key nobody
// asked for, naming the closest known one.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "apps/scene.hpp"
#include "common/errors.hpp"
#include "simulation/parameters.hpp"

namespace mw {

std::string format_scene_number(double v);   // %.10g
std::string json_type_name(const SceneJson& v);  // "a number", "a string \"x\"", ...
// Edits (insert, delete, substitute, swap two neighbours) turning a into b.
std::size_t edit_distance(const std::string& a, const std::string& b);

class Section {
   public:
    // `in`: the object (null: absent, every key at its default); `path`: where it is ("objects[2].lsm");
    // `schema`: the tables' section for it ("objects[].lsm"); `out`: receives the resolved keys.
    Section(const SceneJson* in, std::string path, std::string schema, SceneJson& out, const std::string& source,
            ResolvedKeys& resolved);

    // Every key of `table` in this section, into `target`.
    template <class T>
    void read(const ParamTable<T>& table, T& target) {
        static const T defaults{};
        for (const ParamKey<T>& k : table)
            if (schema_ == k.section) {
                const ParamValue v = value_of(k, [&] { return k.get(defaults); });
                k.set(target, v);
            }
    }
    // One key of `table` (its name) into `target`.
    template <class T>
    ParamValue read_one(const ParamTable<T>& table, const char* name, T& target) {
        static const T defaults{};
        for (const ParamKey<T>& k : table)
            if (schema_ == k.section && std::string(k.name) == name) {
                const ParamValue v = value_of(k, [&] { return k.get(defaults); });
                k.set(target, v);
                return v;
            }
        throw std::logic_error(std::string("no scene key ") + name + " in " + schema_);
    }

    // A nested object (absent: every key at its default).
    Section object(const std::string& key);
    // An array of objects; calls read(section, index) for each element, whose schema is
    // `schema()[]`.
    template <class F>
    void array_of_objects(const std::string& key, F&& read_element);

    // A key read by hand: marks it known and returns it (null when absent).
    const SceneJson* find(const std::string& key);
    // Records a resolved value by hand.
    void record(const std::string& key, SceneJson value) { out_[key] = std::move(value); }
    // Every key present must have been asked for.
    void finish() const;

    [[noreturn]] void fail(const std::string& key_path, const std::string& what) const;
    [[noreturn]] void missing(const std::string& key) const;
    std::string misspelling_hint(const std::string& key) const;
    std::string key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
    const std::string& path() const { return path_; }
    const std::string& schema() const { return schema_; }
    ResolvedKeys& resolved() { return resolved_; }

   private:
    // The key's value from the scene (validated) or its default, recorded as resolved.
    template <class T, class Default>
    ParamValue value_of(const ParamKey<T>& k, Default member_default) {
        const SceneJson* v = find(k.name);
        ParamValue value;
        if (!v) {
            if (k.required) missing(k.name);
            value = k.derived_default ? k.derived_default(resolved_) : member_default();
        } else {
            value = convert(*v, k.name, k.type, k.choices);
        }
        check(k.name, value, k.type, k.range_of ? k.range_of(resolved_) : k.range, k.integer_lo, k.integer_hi);
        resolved_.values[schema_ + "." + k.name] = value;
        out_[k.name] = to_json(value, k.type);
        return value;
    }
    ParamValue convert(const SceneJson& v, const std::string& key, ParamType type,
                       const std::vector<std::string>& choices) const;
    void check(const std::string& key, const ParamValue& value, ParamType type, const ParamRange& range, int lo,
               int hi) const;
    void check_number(const std::string& key_path, double value, const ParamRange& range) const;
    static SceneJson to_json(const ParamValue& value, ParamType type);
    double to_number(const SceneJson& v, const std::string& key_path) const;

    const SceneJson* in_;
    std::string path_, schema_;
    SceneJson& out_;
    const std::string& source_;
    ResolvedKeys& resolved_;
    std::vector<std::string> known_;
    const SceneJson* parent_in_ = nullptr;  // the object holding this one (object() sets it)
    std::string name_in_parent_;
};

template <class F>
void Section::array_of_objects(const std::string& key, F&& read_element) {
    const SceneJson* v = find(key);
    out_[key] = SceneJson::array();
    if (!v) return;
    if (!v->is_array()) fail(key_path(key), "expected an array, got " + json_type_name(*v));
    // Blocks, boxes and objects are checked against each other pairwise; a scene needs tens.
    constexpr std::size_t kMaxElements = 10000;
    if (v->size() > kMaxElements)
        fail(key_path(key), "at most " + std::to_string(kMaxElements) + " elements, got " + std::to_string(v->size()));
    for (std::size_t i = 0; i < v->size(); ++i) {
        SceneJson element;
        Section s(&(*v)[i], key_path(key) + "[" + std::to_string(i) + "]", (schema_.empty() ? key : schema_ + "." + key) + "[]",
                  element, source_, resolved_);
        read_element(s, static_cast<int>(i));
        s.finish();
        out_[key].push_back(element);
    }
}

}  // namespace mw
