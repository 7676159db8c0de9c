// Scene keys declared once. Each module declares the keys it reads in a table of ParamKey (key,
// member, default, range, unit, one line of doc) next to its parameter struct; the scene reader
// (apps/scene.cpp), the resolved scene in summary.json, the bad-input messages and the reference
// table of docs/scenes.md (`meltwater schema --markdown`) all come from the tables. A key's default
// is its member's value in a default-constructed struct, unless the key derives it from keys read
// before it (a support radius twice the spacing).
//
// Host-only and free of JSON: the reader converts JSON to and from ParamValue.
#pragma once
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "algorithms/vec3.hpp"

namespace mw {

// A value as the scene gives it: null, a number, a boolean, a text, a 3-vector or a list of texts.
struct ParamValue {
    enum class Kind { kNull, kNumber, kBoolean, kText, kVector, kTextList } kind = Kind::kNull;
    double number = 0;
    bool boolean = false;
    std::string text;
    std::array<double, 3> vector{0, 0, 0};
    std::vector<std::string> list;

    static ParamValue null() { return ParamValue{}; }
    static ParamValue of(double v) {
        ParamValue p;
        p.kind = Kind::kNumber;
        p.number = v;
        return p;
    }
    static ParamValue of_bool(bool v) {
        ParamValue p;
        p.kind = Kind::kBoolean;
        p.boolean = v;
        return p;
    }
    static ParamValue of(std::string v) {
        ParamValue p;
        p.kind = Kind::kText;
        p.text = std::move(v);
        return p;
    }
    static ParamValue of(Vec3 v) {
        ParamValue p;
        p.kind = Kind::kVector;
        p.vector = {double(v.x), double(v.y), double(v.z)};
        return p;
    }
    static ParamValue of(std::vector<std::string> v) {
        ParamValue p;
        p.kind = Kind::kTextList;
        p.list = std::move(v);
        return p;
    }
};

// An allowed interval for a number; an open end excludes its bound.
struct ParamRange {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool lo_open = false, hi_open = false;

    static ParamRange positive() { return {0, std::numeric_limits<double>::infinity(), true, false}; }
    static ParamRange non_negative() { return {0, std::numeric_limits<double>::infinity(), false, false}; }
    static ParamRange any() { return {}; }
    static ParamRange celsius() { return {-273.15, std::numeric_limits<double>::infinity(), false, false}; }

    bool contains(double v) const {
        if (!std::isfinite(v)) return false;
        if (lo_open ? !(v > lo) : !(v >= lo)) return false;
        if (hi_open ? !(v < hi) : !(v <= hi)) return false;
        return true;
    }
    static std::string number_text(double v) {
        char buffer[64];
        std::snprintf(buffer, sizeof buffer, "%.10g", v);
        return buffer;
    }
    std::string describe() const {
        const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
        if (has_lo && has_hi)
            return std::string("in ") + (lo_open ? "(" : "[") + number_text(lo) + ", " + number_text(hi) +
                   (hi_open ? ")" : "]");
        if (has_lo) return std::string(lo_open ? "> " : ">= ") + number_text(lo);
        if (has_hi) return std::string(hi_open ? "< " : "<= ") + number_text(hi);
        return "finite";
    }
};

// The values of the keys read so far, by path ("fluid.spacing", "objects[].density" for the
// element being read): what a derived default or range is computed from, with the numbers as the
// scene gave them (a Real member would round them).
struct ResolvedKeys {
    std::map<std::string, ParamValue> values;
    int dimensions = 3;  // the scene's: a 2D scene's vectors are [x, y] (z = 0)
    const ParamValue* find(const std::string& path) const {
        auto it = values.find(path);
        return it == values.end() ? nullptr : &it->second;
    }
    double number(const std::string& path) const {
        const ParamValue* v = find(path);
        return v ? v->number : 0.0;
    }
    bool boolean(const std::string& path) const {
        const ParamValue* v = find(path);
        return v && v->boolean;
    }
};

enum class ParamType { kNumber, kInteger, kBoolean, kText, kChoice, kVector, kOptionalNumber, kTextList };

inline const char* param_type_name(ParamType t) {
    switch (t) {
        case ParamType::kNumber: return "number";
        case ParamType::kInteger: return "integer";
        case ParamType::kBoolean: return "boolean";
        case ParamType::kText: return "string";
        case ParamType::kChoice: return "string";
        case ParamType::kVector: return "vector";
        case ParamType::kOptionalNumber: return "number or null";
        case ParamType::kTextList: return "array of strings";
    }
    return "value";
}

// One scene key of a parameter struct T, at `section.name` in the scene ("solver.eta"; an array's
// elements are "objects[]").
template <class T>
struct ParamKey {
    const char* section = "";
    const char* name = "";
    ParamType type = ParamType::kNumber;
    const char* unit = "";
    const char* doc = "";
    ParamRange range;                  // numbers, and every component of a vector
    int integer_lo = 0, integer_hi = 0;  // integers
    std::vector<std::string> choices;  // choices, and the allowed entries of a text list
    bool required = false;             // no default: the scene must give it
    std::function<ParamValue(const T&)> get;
    std::function<void(T&, const ParamValue&)> set;
    // A default derived from keys read before this one (null: the member's value in T{}), and how
    // the docs say it.
    std::function<ParamValue(const ResolvedKeys&)> derived_default;
    std::string default_doc;
    // A range that depends on keys read before this one (null: `range`), and how the docs say it.
    std::function<ParamRange(const ResolvedKeys&)> range_of;
    std::string range_doc;

    ParamKey& derive_default(std::function<ParamValue(const ResolvedKeys&)> f, std::string doc_text) {
        derived_default = std::move(f);
        default_doc = std::move(doc_text);
        return *this;
    }
    ParamKey& derive_range(std::function<ParamRange(const ResolvedKeys&)> f, std::string doc_text) {
        range_of = std::move(f);
        range_doc = std::move(doc_text);
        return *this;
    }
    ParamKey& must_be_given() {
        required = true;
        return *this;
    }
    std::string path() const { return std::string(section) + (section[0] ? "." : "") + name; }
};

template <class T>
using ParamTable = std::vector<ParamKey<T>>;

// A float's shortest decimal that reads back as the same float, as a double (0.4f is 0.4, not
// 0.4000000059604645): how a Real parameter is written into the resolved scene.
inline double shortest_decimal(float v) {
    if (!std::isfinite(v)) return double(v);
    char buffer[32];
    for (int digits = 1; digits <= 9; ++digits) {
        std::snprintf(buffer, sizeof buffer, "%.*g", digits, double(v));
        const double back = std::strtod(buffer, nullptr);
        if (static_cast<float>(back) == v) return back;
    }
    return double(v);
}
inline double shortest_decimal(double v) { return v; }

// Builders. `access` is a generic callable returning a reference to the member in a T (const or
// not), so that a key may sit anywhere inside T; each builder also takes a member pointer.
// A number (Real or double), an integer in [lo, hi], a boolean, a text, a choice among named
// values of an enum, a 3-vector, a number that may be null, a list of texts each one of `allowed`.
template <class T, class Access>
ParamKey<T> number_key(const char* section, const char* name, Access access, ParamRange range, const char* unit,
                       const char* doc) {
    ParamKey<T> k;
    k.section = section, k.name = name, k.type = ParamType::kNumber, k.unit = unit, k.doc = doc, k.range = range;
    k.get = [access](const T& t) { return ParamValue::of(shortest_decimal(access(t))); };
    k.set = [access](T& t, const ParamValue& v) {
        using M = std::decay_t<decltype(access(t))>;
        access(t) = static_cast<M>(v.number);
    };
    return k;
}
template <class T, class Access>
ParamKey<T> integer_key(const char* section, const char* name, Access access, int lo, int hi, const char* doc) {
    ParamKey<T> k;
    k.section = section, k.name = name, k.type = ParamType::kInteger, k.doc = doc;
    k.integer_lo = lo, k.integer_hi = hi;
    k.get = [access](const T& t) { return ParamValue::of(double(access(t))); };
    k.set = [access](T& t, const ParamValue& v) { access(t) = static_cast<int>(v.number); };
    return k;
}
template <class T, class Access>
ParamKey<T> boolean_key(const char* section, const char* name, Access access, const char* doc) {
    ParamKey<T> k;
    k.section = section, k.name = name, k.type = ParamType::kBoolean, k.doc = doc;
    k.get = [access](const T& t) { return ParamValue::of_bool(access(t)); };
    k.set = [access](T& t, const ParamValue& v) { access(t) = v.boolean; };
    return k;
}
template <class T, class Access>
ParamKey<T> text_key(const char* section, const char* name, Access access, const char* doc) {
    ParamKey<T> k;
    k.section = section, k.name = name, k.type = ParamType::kText, k.doc = doc;
    k.get = [access](const T& t) { return ParamValue::of(std::string(access(t))); };
    k.set = [access](T& t, const ParamValue& v) { access(t) = v.text; };
    return k;
}
template <class T, class E, class Access>
ParamKey<T> choice_key(const char* section, const char* name, Access access,
                       std::vector<std::pair<std::string, E>> options, const char* doc) {
    ParamKey<T> k;
    k.section = section, k.name = name, k.type = ParamType::kChoice, k.doc = doc;
    for (const auto& o : options) k.choices.push_back(o.first);
    k.get = [access, options](const T& t) {
        for (const auto& o : options)
            if (o.second == access(t)) return ParamValue::of(o.first);
        return ParamValue::of(options.front().first);
    };
    k.set = [access, options](T& t, const ParamValue& v) {
        for (const auto& o : options)
            if (o.first == v.text) access(t) = o.second;
    };
    return k;
}
template <class T, class Access>
ParamKey<T> vector_key(const char* section, const char* name, Access access, ParamRange range, const char* unit,
                       const char* doc) {
    ParamKey<T> k;
    k.section = section, k.name = name, k.type = ParamType::kVector, k.unit = unit, k.doc = doc, k.range = range;
    k.get = [access](const T& t) {
        const Vec3 v = access(t);
        ParamValue p = ParamValue::of(v);
        p.vector = {shortest_decimal(v.x), shortest_decimal(v.y), shortest_decimal(v.z)};
        return p;
    };
    k.set = [access](T& t, const ParamValue& v) {
        access(t) = Vec3{Real(v.vector[0]), Real(v.vector[1]), Real(v.vector[2])};
    };
    return k;
}
template <class T, class Access>
ParamKey<T> optional_number_key(const char* section, const char* name, Access access, ParamRange range,
                                const char* unit, const char* doc) {
    ParamKey<T> k;
    k.section = section, k.name = name, k.type = ParamType::kOptionalNumber, k.unit = unit, k.doc = doc;
    k.range = range;
    k.get = [access](const T& t) { return access(t) ? ParamValue::of(*access(t)) : ParamValue::null(); };
    k.set = [access](T& t, const ParamValue& v) {
        using M = std::decay_t<decltype(access(t))>;
        access(t) = v.kind == ParamValue::Kind::kNull ? M{} : M(v.number);
    };
    return k;
}
template <class T, class Access>
ParamKey<T> text_list_key(const char* section, const char* name, Access access, std::vector<std::string> allowed,
                          const char* doc) {
    ParamKey<T> k;
    k.section = section, k.name = name, k.type = ParamType::kTextList, k.doc = doc, k.choices = std::move(allowed);
    k.get = [access](const T& t) { return ParamValue::of(std::vector<std::string>(access(t))); };
    k.set = [access](T& t, const ParamValue& v) { access(t) = v.list; };
    return k;
}

// The member of T that `member` points to, as an accessor for the builders above.
template <class T, class M>
auto member(M T::*pointer) {
    return [pointer](auto& t) -> auto& { return t.*pointer; };
}

// A key's row of the reference table: its path, type, default, what is allowed, unit and doc.
struct ParamDoc {
    std::string path, type, default_text, allowed, unit, doc;
};

inline std::string param_value_text(const ParamValue& v) {
    switch (v.kind) {
        case ParamValue::Kind::kNull: return "null";
        case ParamValue::Kind::kNumber: return ParamRange::number_text(v.number);
        case ParamValue::Kind::kBoolean: return v.boolean ? "true" : "false";
        case ParamValue::Kind::kText: return "\"" + v.text + "\"";
        case ParamValue::Kind::kVector:
            return "[" + ParamRange::number_text(v.vector[0]) + ", " + ParamRange::number_text(v.vector[1]) + ", " +
                   ParamRange::number_text(v.vector[2]) + "]";
        case ParamValue::Kind::kTextList: {
            std::string s = "[";
            for (std::size_t k = 0; k < v.list.size(); ++k) s += (k ? ", \"" : "\"") + v.list[k] + "\"";
            return s + "]";
        }
    }
    return "";
}

// The rows of a table, with defaults read from `defaults` (a default-constructed T).
template <class T>
std::vector<ParamDoc> param_docs(const ParamTable<T>& table, const T& defaults = T{}) {
    std::vector<ParamDoc> rows;
    for (const ParamKey<T>& k : table) {
        ParamDoc d;
        d.path = k.path();
        d.type = param_type_name(k.type);
        d.default_text = k.required ? "required" : !k.default_doc.empty() ? k.default_doc : param_value_text(k.get(defaults));
        if (!k.range_doc.empty()) {
            d.allowed = k.range_doc;
        } else if (k.type == ParamType::kInteger) {
            d.allowed = "[" + std::to_string(k.integer_lo) + ", " + std::to_string(k.integer_hi) + "]";
        } else if (k.type == ParamType::kChoice || k.type == ParamType::kTextList) {
            for (std::size_t c = 0; c < k.choices.size(); ++c) d.allowed += (c ? ", \"" : "\"") + k.choices[c] + "\"";
        } else if (k.type == ParamType::kNumber || k.type == ParamType::kOptionalNumber ||
                   k.type == ParamType::kVector) {
            d.allowed = k.range.describe();
        }
        d.unit = k.unit;
        d.doc = k.doc;
        rows.push_back(std::move(d));
    }
    return rows;
}

}  // namespace mw
