#include "apps/scene.hpp"
#include "surface/fluid_surface.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <unordered_set>

#include "common/errors.hpp"
#include "sampling/wall_gap.hpp"

namespace mw {

namespace {

const char* kDefaultScene =
#include "default_scene.inc"
    ;

std::string format_number(double v) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.10g", v);
    return buffer;
}

std::string type_name(const SceneJson& v) {
    if (v.is_null()) return "null";
    if (v.is_boolean()) return "a boolean";
    if (v.is_number_integer() || v.is_number_unsigned()) return "an integer";
    if (v.is_number()) return "a number";
    if (v.is_string()) return "a string \"" + v.get<std::string>() + "\"";
    if (v.is_array()) return "an array";
    return "an object";
}

// An allowed interval for a number; an open end excludes its bound.
struct Range {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool lo_open = false, hi_open = false;

    static Range positive() { return {0, std::numeric_limits<double>::infinity(), true, false}; }
    static Range non_negative() { return {0, std::numeric_limits<double>::infinity(), false, false}; }
    static Range any() { return {}; }

    bool contains(double v) const {
        if (!std::isfinite(v)) return false;
        if (lo_open ? !(v > lo) : !(v >= lo)) return false;
        if (hi_open ? !(v < hi) : !(v <= hi)) return false;
        return true;
    }
    std::string describe() const {
        const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
        if (has_lo && has_hi)
            return std::string("in ") + (lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) +
                   (hi_open ? ")" : "]");
        if (has_lo) return std::string(lo_open ? "> " : ">= ") + format_number(lo);
        if (has_hi) return std::string(hi_open ? "< " : "<= ") + format_number(hi);
        return "finite";
    }
};

// Temperatures are in °C: not below absolute zero.
const Range kTemperatureRange{-273.15, std::numeric_limits<double>::infinity(), false, false};

// A number the simulation's scalar type (Real) holds: in range after the conversion, and not so
// small that it would turn into zero or a subnormal (a time step of 1e-300, say).
bool representable(double v) {
    const double magnitude = std::fabs(v);
    return magnitude == 0 || (magnitude <= double(std::numeric_limits<Real>::max()) &&
                              magnitude >= double(std::numeric_limits<Real>::min()));
}
std::string representable_range() {
    return std::string("outside what the simulation's ") + (sizeof(Real) == 4 ? "float" : "double") +
           " numbers hold (magnitudes " + format_number(double(std::numeric_limits<Real>::min())) + " to " +
           format_number(double(std::numeric_limits<Real>::max())) + ", or 0)";
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

// Edits (insert, delete, substitute, swap two neighbours) turning a into b: how a misspelt key
// is recognised.
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

// A key of `object` that looks like a misspelling of `wanted` (and is not a key read already),
// or "". Short keys allow one edit, longer ones two: "min" is not a misspelling of "max".
std::string misspelling_of(const std::string& wanted, const SceneJson* object, const std::vector<std::string>& known) {
    if (!object || !object->is_object()) return "";
    for (auto it = object->begin(); it != object->end(); ++it) {
        if (it.key() == wanted || std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
        if (edit_distance(it.key(), wanted) <= (wanted.size() >= 6 ? 2u : 1u)) return it.key();
    }
    return "";
}

// One JSON object of the scene being read. Each getter validates one key, records its resolved
// value in `out`, and marks the key as known; finish() rejects every key nobody asked for.
class Section {
   public:
    Section(const SceneJson* in, std::string path, SceneJson& out, const std::string& source)
        : in_(in), path_(std::move(path)), out_(out), source_(source) {
        if (in_ && !in_->is_object()) fail(path_, "expected an object, got " + type_name(*in_));
        out_ = SceneJson::object();
    }

    // A number must lie in its range and fit the simulation's scalar type.
    void check_value(const std::string& key_path, double value, const Range& range) const {
        if (!range.contains(value)) fail(key_path, "must be " + range.describe() + ", got " + format_number(value));
        if (!representable(value)) fail(key_path, format_number(value) + " is " + representable_range());
    }

    [[noreturn]] void fail(const std::string& key_path, const std::string& what) const {
        throw InputError(source_ + ": " + (key_path.empty() ? std::string("scene") : key_path) + ": " + what);
    }
    std::string key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

    // "required key is missing", with the key the user probably meant it to be, if any.
    [[noreturn]] void missing(const std::string& key) const {
        std::string hint = misspelling_hint(key);
        // A whole section absent: its misspelt name sits in the parent.
        if (hint.empty() && !in_ && parent_in_) {
            const std::string near = misspelling_of(name_in_parent_, parent_in_, {});
            if (!near.empty())
                hint = " (there is no \"" + name_in_parent_ + "\"; is \"" + near + "\" a misspelling of it?)";
        }
        fail(key_path(key), "required key is missing" + hint);
    }
    std::string misspelling_hint(const std::string& key) const {
        const std::string near = misspelling_of(key, in_, known_);
        return near.empty() ? "" : " (is \"" + near + "\" a misspelling of it?)";
    }

    const SceneJson* find(const std::string& key) {
        known_.push_back(key);
        if (!in_) return nullptr;
        auto it = in_->find(key);
        return it == in_->end() ? nullptr : &*it;
    }
    const SceneJson& require(const std::string& key) {
        const SceneJson* v = find(key);
        if (!v) missing(key);
        return *v;
    }

    double number(const std::string& key, std::optional<double> fallback, const Range& range) {
        const SceneJson* v = find(key);
        if (!v && !fallback) missing(key);
        const double value = v ? to_number(*v, key_path(key)) : *fallback;
        check_value(key_path(key), value, range);
        out_[key] = value;
        return value;
    }

    // A number that may be absent or null, meaning "none" (resolved as null, so that --set finds
    // the key).
    std::optional<double> optional_number(const std::string& key, const Range& range) {
        const SceneJson* v = find(key);
        if (!v || v->is_null()) {
            out_[key] = nullptr;
            return std::nullopt;
        }
        return number(key, std::nullopt, range);
    }

    int integer(const std::string& key, int fallback, int lo, int hi) {
        const SceneJson* v = find(key);
        int value = fallback;
        if (v) {
            const double d = to_number(*v, key_path(key));
            if (d != std::floor(d)) fail(key_path(key), "expected an integer, got " + format_number(d));
            if (d < lo || d > hi)
                fail(key_path(key), "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                                        format_number(d));
            value = static_cast<int>(d);
        }
        out_[key] = value;
        return value;
    }

    bool boolean(const std::string& key, bool fallback) {
        const SceneJson* v = find(key);
        bool value = fallback;
        if (v) {
            if (!v->is_boolean()) fail(key_path(key), "expected true or false, got " + type_name(*v));
            value = v->get<bool>();
        }
        out_[key] = value;
        return value;
    }

    std::string string(const std::string& key, const std::string& fallback) {
        const SceneJson* v = find(key);
        std::string value = fallback;
        if (v) {
            if (!v->is_string()) fail(key_path(key), "expected a string, got " + type_name(*v));
            value = v->get<std::string>();
            // A Latin-1 byte (a --set value that is not JSON is taken as plain text) would
            // otherwise only fail when summary.json is written, after the run.
            if (!valid_utf8(value)) fail(key_path(key), "the text is not valid UTF-8");
        }
        out_[key] = value;
        return value;
    }

    std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed) {
        const SceneJson* v = find(key);
        std::string value = fallback;
        if (v) {
            if (!v->is_string()) fail(key_path(key), "expected one of " + join(allowed) + ", got " + type_name(*v));
            value = v->get<std::string>();
            bool ok = false;
            for (const auto& a : allowed) ok = ok || a == value;
            if (!ok) fail(key_path(key), "expected one of " + join(allowed) + ", got \"" + value + "\"");
        }
        out_[key] = value;
        return value;
    }

    // A 3-vector [x, y, z]; each component in `range`.
    Vec3 vec3(const std::string& key, std::optional<std::array<double, 3>> fallback, const Range& range = Range::any()) {
        const SceneJson* v = find(key);
        if (!v && !fallback) missing(key);
        double c[3];
        if (v) {
            if (!v->is_array() || v->size() != 3)
                fail(key_path(key), "expected an array of 3 numbers [x, y, z], got " +
                                        (v->is_array() ? "an array of " + std::to_string(v->size()) : type_name(*v)));
            for (int a = 0; a < 3; ++a) {
                const std::string p = key_path(key) + "[" + std::to_string(a) + "]";
                c[a] = to_number((*v)[a], p);
                check_value(p, c[a], range);
            }
        } else {
            c[0] = (*fallback)[0], c[1] = (*fallback)[1], c[2] = (*fallback)[2];
        }
        out_[key] = SceneJson::array({c[0], c[1], c[2]});
        return Vec3{Real(c[0]), Real(c[1]), Real(c[2])};
    }

    // A nested object (absent = every key at its default).
    Section object(const std::string& key) {
        const SceneJson* v = find(key);
        Section child(v, key_path(key), out_[key], source_);
        child.parent_in_ = in_;
        child.name_in_parent_ = key;
        return child;
    }

    // An array of objects; calls read(section, index) for each element.
    template <class F>
    void array_of_objects(const std::string& key, F&& read) {
        const SceneJson* v = find(key);
        out_[key] = SceneJson::array();
        if (!v) return;
        if (!v->is_array()) fail(key_path(key), "expected an array, got " + type_name(*v));
        // Blocks, boxes and objects are checked against each other pairwise; a scene needs tens.
        constexpr std::size_t kMaxElements = 10000;
        if (v->size() > kMaxElements)
            fail(key_path(key), "at most " + std::to_string(kMaxElements) + " elements, got " + std::to_string(v->size()));
        for (std::size_t i = 0; i < v->size(); ++i) {
            SceneJson element;
            Section s(&(*v)[i], key_path(key) + "[" + std::to_string(i) + "]", element, source_);
            read(s, static_cast<int>(i));
            s.finish();
            out_[key].push_back(element);
        }
    }

    // An array of strings, each one of `allowed`.
    std::vector<std::string> string_list(const std::string& key, const std::vector<std::string>& fallback,
                                         const std::vector<std::string>& allowed) {
        const SceneJson* v = find(key);
        std::vector<std::string> value = fallback;
        if (v) {
            if (!v->is_array()) fail(key_path(key), "expected an array of strings, got " + type_name(*v));
            value.clear();
            for (std::size_t i = 0; i < v->size(); ++i) {
                const std::string p = key_path(key) + "[" + std::to_string(i) + "]";
                const SceneJson& e = (*v)[i];
                if (!e.is_string()) fail(p, "expected one of " + join(allowed) + ", got " + type_name(e));
                bool ok = false;
                for (const auto& a : allowed) ok = ok || a == e.get<std::string>();
                if (!ok) fail(p, "expected one of " + join(allowed) + ", got \"" + e.get<std::string>() + "\"");
                value.push_back(e.get<std::string>());
            }
        }
        out_[key] = value;
        return value;
    }

    // Every key present must have been asked for.
    void finish() const {
        if (!in_) return;
        for (auto it = in_->begin(); it != in_->end(); ++it) {
            bool ok = false;
            for (const auto& k : known_) ok = ok || k == it.key();
            if (!ok) fail(key_path(it.key()), "unknown key (allowed here: " + join(known_) + ")");
        }
    }

    const std::string& path() const { return path_; }

   private:
    double to_number(const SceneJson& v, const std::string& p) const {
        if (!v.is_number()) fail(p, "expected a number, got " + type_name(v));
        return v.get<double>();
    }
    static std::string join(const std::vector<std::string>& items) {
        std::string s;
        for (const auto& i : items) s += (s.empty() ? "" : ", ") + i;
        return s;
    }

    const SceneJson* in_;
    std::string path_;
    SceneJson& out_;
    const std::string& source_;
    std::vector<std::string> known_;
    const SceneJson* parent_in_ = nullptr;  // the object holding this one (object() sets it)
    std::string name_in_parent_;
};

Vec3 checked_box(Section& s, Vec3 lo, Vec3 hi) {
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
        s.fail(s.key_path("max"), "must exceed min on every axis");
    return hi;
}

std::string describe_box(Vec3 lo, Vec3 hi) {
    char buffer[160];  // Real may be float: 6 digits keep 1.6 from printing as 1.600000024
    std::snprintf(buffer, sizeof buffer, "[%.6g, %.6g, %.6g] to [%.6g, %.6g, %.6g]", double(lo.x), double(lo.y),
                  double(lo.z), double(hi.x), double(hi.y), double(hi.z));
    return buffer;
}

std::string describe_point(Vec3 p) {
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, "[%.6g, %.6g, %.6g]", double(p.x), double(p.y), double(p.z));
    return buffer;
}

bool inside(Vec3 lo, Vec3 hi, Vec3 dlo, Vec3 dhi) {
    const Real eps = Real(1e-6);
    return lo.x >= dlo.x - eps && lo.y >= dlo.y - eps && lo.z >= dlo.z - eps && hi.x <= dhi.x + eps &&
           hi.y <= dhi.y + eps && hi.z <= dhi.z + eps;
}

// ---- One small function per section (a later `objects` section slots in beside these) ----------

void read_domain(Section s, Scene& scene) {
    scene.params.domain_min = s.vec3("min", std::nullopt);
    scene.params.domain_max = checked_box(s, scene.params.domain_min, s.vec3("max", std::nullopt));
    s.finish();
}

void read_fluid(Section s, Scene& scene) {
    FluidParams& f = scene.params.fluid;
    f.rest_density = Real(s.number("rest_density", 1000.0, Range::positive()));
    const double r0 = s.number("spacing", std::nullopt, Range::positive());
    f.spacing = Real(r0);
    f.support_radius = Real(s.number("support_radius", 2 * r0, Range{r0, 4 * r0, true, false}));
    // The names are kernel_name()'s, so the resolved scene and `info` spell them alike.
    const std::string cubic = kernel_name(KernelKind::kCubicSpline), wendland = kernel_name(KernelKind::kWendlandC2);
    f.kernel = s.choice("kernel", cubic, {cubic, wendland}) == wendland ? KernelKind::kWendlandC2
                                                                        : KernelKind::kCubicSpline;
    f.viscosity = Real(s.number("viscosity", 0.0, Range::non_negative()));
    f.wall_viscosity = Real(s.number("wall_viscosity", 0.0, Range::non_negative()));
    // With heat.enabled only (docs/heat.md): the fluid blocks' default temperature, and the
    // fluid's thermal diffusivity and heat capacity per volume (water's at 20 °C by default).
    scene.fluid_temperature = Real(s.number("temperature", 20.0, kTemperatureRange));
    scene.params.heat.fluid_diffusivity = Real(s.number("thermal_diffusivity", 1.43e-7, Range::non_negative()));
    scene.params.heat.fluid_capacity = Real(s.number("heat_capacity", 4.18e6, Range::positive()));
    s.finish();
}

void read_solver(Section s, Scene& scene) {
    SolverParams& p = scene.params.solver;
    // Below 1e-7 s a second of simulated time would take ten million steps: a typo, not a choice.
    p.dt = Real(s.number("dt", 0.001, Range{1e-7, 1, false, false}));
    p.dt_mode = s.choice("dt_mode", "fixed", {"fixed", "cfl"}) == "cfl" ? TimeStepMode::kCfl : TimeStepMode::kFixed;
    p.cfl_number = Real(s.number("cfl_number", 0.4, Range{0, 1, true, false}));
    const double eta = s.number("eta", 0.01, Range{0, 1, true, true});
    p.eta = Real(eta);
    p.eta_max = Real(s.number("eta_max", default_eta_max(eta), Range{0, 1, false, true}));
    p.min_iterations = s.integer("min_iterations", 3, 1, 1000);
    p.max_iterations = s.integer("max_iterations", 100, 1, 10000);
    if (p.max_iterations < p.min_iterations)
        s.fail(s.key_path("max_iterations"), "must be >= min_iterations (" + std::to_string(p.min_iterations) +
                                                 "), got " + std::to_string(p.max_iterations));
    scene.max_density_error = s.number("max_density_error", 1.0, Range::positive());
    scene.max_speed = s.optional_number("max_speed", Range::positive());
    s.finish();
}

void read_boundary(Section s, Scene& scene) {
    scene.walls = s.boolean("walls", true);
    scene.boundary_spacing_factor = Real(s.number("spacing_factor", 0.5, Range{0, 1, true, false}));
    scene.boundary_layers = s.integer("layers", 1, 1, 8);
    scene.params.wall_correction = s.boolean("correction", false);  // off unless the scene asks (the shipped scenes do)
    scene.max_lost_fraction = s.number("max_lost_fraction", scene.walls ? 0.01 : 1.0, Range{0, 1});
    s.finish();
}

// How fluid and moving solids act on each other (docs/scenes.md, "coupling").
void read_coupling(Section s, Scene& scene) {
    // Off unless the scene asks, like every physics switch added after the first release
    // (scenes/floating_boxes.json asks).
    scene.params.two_way_coupling = s.boolean("two_way", false);
    scene.params.solid_correction = s.boolean("correction", false);
    scene.params.solid_slip = Real(s.number("slip", 1.0, Range{0, 1}));
    // Off unless asked for too, though without it a solid entering the fluid at the CFL step can
    // blow the pool up (docs/coupling.md, "Solids met where they will be"); `meltwater info` says so.
    scene.params.solid_prediction = s.boolean("predict_solids", false);
    s.finish();
}

// Heat conduction (docs/heat.md): off unless the scene asks, like every physics switch added after
// the first release; the materials' temperatures and diffusivities are read with the materials.
void read_heat(Section s, Scene& scene) {
    scene.params.heat.enabled = s.boolean("enabled", false);
    scene.params.heat.max_substeps = s.integer("max_substeps", 32, 1, 1000);
    s.finish();
}

void read_neighbors(Section s, Scene& scene) {
    scene.params.ordering =
        s.choice("ordering", "zorder", {"zorder", "linear"}) == "linear" ? CellOrdering::kLinear : CellOrdering::kZOrder;
    scene.params.cells_per_support = s.integer("cells_per_support", 1, 1, 2);
    const std::string lists = s.choice("lists", "auto", {"auto", "on", "off"});
    scene.params.neighbor_lists = lists == "on"    ? SimulationParams::Lists::kOn
                                  : lists == "off" ? SimulationParams::Lists::kOff
                                                   : SimulationParams::Lists::kAuto;
    s.finish();
}

// Refuses a block [lo, hi] that shares volume with a fluid block read so far (touching faces do
// not count): two lattices in one place have a density far above rest that PCISPH resolves by an
// explosion. (Static boxes and objects may overlap the fluid: build_setup carves it out.)
void check_clear_of_fluid_blocks(const Section& s, const Scene& scene, Vec3 lo, Vec3 hi) {
    for (std::size_t k = 0; k < scene.fluid_blocks.size(); ++k) {
        const FluidBlock& f = scene.fluid_blocks[k];
        if (lo.x < f.max.x && f.min.x < hi.x && lo.y < f.max.y && f.min.y < hi.y && lo.z < f.max.z && f.min.z < hi.z)
            s.fail(s.path(), "overlaps fluid_blocks[" + std::to_string(k) + "] " + describe_box(f.min, f.max) +
                                 "; blocks may touch but not overlap");
    }
}

void read_fluid_blocks(Section& root, Scene& scene) {
    root.array_of_objects("fluid_blocks", [&](Section& s, int) {
        FluidBlock b;
        b.min = s.vec3("min", std::nullopt);
        b.max = checked_box(s, b.min, s.vec3("max", std::nullopt));
        b.velocity = s.vec3("velocity", std::array<double, 3>{0, 0, 0});
        b.temperature = Real(s.number("temperature", double(scene.fluid_temperature), kTemperatureRange));
        if (!inside(b.min, b.max, scene.params.domain_min, scene.params.domain_max))
            s.fail(s.path(), "the block must lie inside the domain " + describe_box(scene.params.domain_min, scene.params.domain_max));
        check_clear_of_fluid_blocks(s, scene, b.min, b.max);
        scene.fluid_blocks.push_back(b);
    });
}

void read_static_boxes(Section& root, Scene& scene) {
    root.array_of_objects("static_boxes", [&](Section& s, int) {
        StaticBox b;
        b.min = s.vec3("min", std::nullopt);
        b.max = checked_box(s, b.min, s.vec3("max", std::nullopt));
        b.layers = s.integer("layers", scene.boundary_layers, 1, 8);
        if (!inside(b.min, b.max, scene.params.domain_min, scene.params.domain_max))
            s.fail(s.path(), "the box must lie inside the domain " + describe_box(scene.params.domain_min, scene.params.domain_max));
        scene.static_boxes.push_back(b);
    });
}

void read_object_mesh(Section s, SceneObject& o) {
    o.mesh_file = s.string("file", "");
    o.mesh_procedural = s.string("procedural", "");
    if (o.mesh_file.empty() == o.mesh_procedural.empty())
        s.fail(s.path(), "give exactly one of \"file\" (an OBJ file) or \"procedural\" (e.g. \"sphere:radius=0.1\")" +
                             s.misspelling_hint(o.mesh_file.empty() ? "file" : "procedural"));
    s.finish();
}

void read_object_transform(Section s, SceneObject& o) {
    const Vec3 scale = s.vec3("scale", std::array<double, 3>{1, 1, 1});
    if (scale.x == 0 || scale.y == 0 || scale.z == 0) s.fail(s.key_path("scale"), "must be non-zero on every axis");
    const Vec3 rotation = s.vec3("rotation_deg", std::array<double, 3>{0, 0, 0});
    const Vec3 translation = s.vec3("translation", std::array<double, 3>{0, 0, 0});
    o.scale = {scale.x, scale.y, scale.z};
    o.rotation_deg = {rotation.x, rotation.y, rotation.z};
    o.translation = {translation.x, translation.y, translation.z};
    s.finish();
}

void read_object_lsm(Section s, SceneObject& o) {
    o.region_half_width = s.integer("w", 2, 1, 8);
    o.stiffness = Real(s.number("alpha", 1.0, Range{0, 1, true, false}));
    o.damping = Real(s.number("damping", 0.0, Range::non_negative()));
    o.wall_friction = Real(s.number("wall_friction", 0.2, Range{0, 1, false, false}));
    s.finish();
}

void read_object_pinned(Section s, SceneObject& o) {
    const bool has_box = s.find("box") != nullptr, has_half = s.find("half_space") != nullptr;
    if (has_box && has_half) s.fail(s.path(), "give either \"box\" or \"half_space\", not both");
    if (has_box) {
        Section b = s.object("box");
        o.pin = SceneObject::Pin::kBox;
        o.pin_min = b.vec3("min", std::nullopt);
        o.pin_max = checked_box(b, o.pin_min, b.vec3("max", std::nullopt));
        b.finish();
    }
    if (has_half) {
        Section h = s.object("half_space");
        o.pin = SceneObject::Pin::kHalfSpace;
        o.pin_point = h.vec3("point", std::nullopt);
        o.pin_normal = h.vec3("normal", std::nullopt);
        if (!(norm(o.pin_normal) > 0)) h.fail(h.key_path("normal"), "must be non-zero");
        h.finish();
    }
    s.finish();
}

// `name` of an object or emitter: letters, digits, '_' and '-' only, `fallback` when absent, and
// none of the names in `taken` (what `plural` lists so far).
template <class Named>
std::string read_unique_name(Section& s, const std::string& fallback, const std::vector<Named>& taken,
                             const std::string& plural, const std::string& why) {
    const std::string name = s.string("name", fallback);
    if (name.empty() ||
        name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") != std::string::npos)
        s.fail(s.key_path("name"), "use letters, digits, '_' and '-' only" + why + ", got \"" + name + "\"");
    for (const Named& other : taken)
        if (other.name == name) s.fail(s.key_path("name"), "two " + plural + " are named \"" + name + "\"");
    return name;
}

void read_objects(Section& root, Scene& scene) {
    root.array_of_objects("objects", [&](Section& s, int index) {
        SceneObject o;
        o.name = read_unique_name(s, "object" + std::to_string(index), scene.objects, "objects", " (it names output files)");
        read_object_mesh(s.object("mesh"), o);
        read_object_transform(s.object("transform"), o);
        const std::string kind = s.choice("kind", "elastic", {"elastic", "rigid", "static"});
        o.kind = kind == "rigid" ? SolidKind::kRigid : kind == "static" ? SolidKind::kStatic : SolidKind::kElastic;
        o.density = Real(s.number("density", 1000.0, Range::positive()));
        o.velocity = s.vec3("velocity", std::array<double, 3>{0, 0, 0});
        o.interface_tension = Real(s.number("interface_tension", 0.0, Range::non_negative()));
        if (o.kind == SolidKind::kStatic && o.interface_tension > 0)
            s.fail(s.key_path("interface_tension"), "is for elastic and rigid objects (this one is static)");
        o.temperature = Real(s.number("temperature", double(scene.fluid_temperature), kTemperatureRange));
        o.thermal_diffusivity = Real(s.number("thermal_diffusivity", double(scene.params.heat.fluid_diffusivity),
                                              Range::non_negative()));
        o.heat_capacity = Real(s.number("heat_capacity", double(scene.params.heat.fluid_capacity), Range::positive()));
        // Melting (docs/melting.md): an elastic object in a scene that conducts heat.
        if (const std::optional<double> melting_point = s.optional_number("melting_point", kTemperatureRange)) {
            o.melting_point = Real(*melting_point);
            if (o.kind != SolidKind::kElastic)
                s.fail(s.key_path("melting_point"), "is for elastic objects (this one is " + kind + ")");
            if (!scene.params.heat.enabled)
                s.fail(s.key_path("melting_point"), "needs heat conduction: set heat.enabled to true");
        }
        o.latent_heat = Real(s.number("latent_heat", 0.0, Range::non_negative()));
        if (o.latent_heat > 0 && !o.melts())
            s.fail(s.key_path("latent_heat"), "needs a melting_point");
        read_object_lsm(s.object("lsm"), o);
        read_object_pinned(s.object("pinned"), o);
        scene.objects.push_back(o);
    });
}

void read_run(Section s, Scene& scene) {
    scene.end_time = s.number("end_time", 1.0, Range{0, 1e6, true, false});  // 1e6 s keeps step counts in range
    s.finish();
}

// After read_run: an emitter's end defaults to the run's.
void read_emitters(Section& root, Scene& scene) {
    root.array_of_objects("emitters", [&](Section& s, int index) {
        if (std::size_t(index) >= kMaxEmitters)
            s.fail(s.path(), "at most " + std::to_string(kMaxEmitters) + " emitters are supported");
        SceneEmitter e;
        e.name = read_unique_name(s, "emitter" + std::to_string(index), scene.emitters, "emitters", "");
        e.center = s.vec3("center", std::nullopt);
        const Vec3 direction = s.vec3("direction", std::nullopt);
        if (!(norm(direction) > 0)) s.fail(s.key_path("direction"), "must not be zero");
        e.direction = (Real(1) / norm(direction)) * direction;
        const double radius = s.number("radius", std::nullopt, Range::positive());
        e.radius = Real(radius);
        e.speed = Real(s.number("speed", std::nullopt, Range{0, 1000, true, false}));
        e.start = s.number("start", 0.0, Range{0, 1e6, false, false});
        e.end = s.number("end", scene.end_time, Range{0, 1e6, true, false});
        if (!(e.end > e.start))
            s.fail(s.key_path("end"), "must be later than start (" + format_number(e.start) + " s), got " +
                                          format_number(e.end));
        e.temperature = Real(s.number("temperature", double(scene.fluid_temperature), kTemperatureRange));
        // The disc's particles start r0/2 inside the domain at the most, as a fluid block's do.
        const double margin = 0.5 * double(scene.params.fluid.spacing) * (1 - 1e-6);
        const Vec3 lo = scene.params.domain_min, hi = scene.params.domain_max;
        const double n[3] = {e.direction.x, e.direction.y, e.direction.z}, c[3] = {e.center.x, e.center.y, e.center.z},
                     low[3] = {lo.x, lo.y, lo.z}, high[3] = {hi.x, hi.y, hi.z};
        for (int a = 0; a < 3; ++a) {
            // How far the disc reaches along axis a: radius × sin(angle between the axis and its normal).
            const double extent = radius * std::sqrt(std::max(0.0, 1 - n[a] * n[a]));
            if (c[a] - extent < low[a] + margin || c[a] + extent > high[a] - margin)
                s.fail(s.path(), "the disc (center " + describe_point(e.center) + ", radius " + format_number(radius) +
                                     ") must lie inside the domain " + describe_box(lo, hi) + ", r0/2 from its faces");
        }
        scene.emitters.push_back(e);
    });
}

void read_output(Section s, Scene& scene) {
    scene.fps = s.number("fps", 30.0, Range{0, 10000, true, false});
    scene.formats = s.string_list("formats", {"vtu"}, {"vtu", "surface"});
    Section surface = s.object("surface");
    scene.surface_voxel = surface.number("voxel", 0.5, Range{0.1, 4, false, false});
    surface.finish();
    s.finish();
}

// ---- --set overrides ---------------------------------------------------------------------------

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

std::string read_file(const std::string& path) {
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

}  // namespace

Real Scene::wall_gap() const {
    return rest_density_wall_gap(params.fluid.spacing, params.fluid.support_radius, boundary_spacing(),
                                 boundary_layers, params.fluid.kernel);
}

std::string Scene::kernel_warning() const {
    const FluidParams& f = params.fluid;
    const double width = double(f.support_radius) / double(f.spacing);
    if (f.kernel != KernelKind::kCubicSpline || width <= 2.25 + 1e-6) return "";
    char text[400];
    std::snprintf(text, sizeof text,
                  "fluid.kernel \"cubic_spline\" with h = %.3g r0: wider than 2.25 r0 the cubic spline risks the "
                  "pairing instability (at 2.5 r0 the default dam break throws a particle at 30 m/s within 30 ms, at 241 m/s without boundary.correction); "
                  "fluid.kernel \"wendland_c2\" has none (docs/solver.md, \"Kernels\")",
                  width);
    return text;
}

double Scene::largest_heat_diffusivity() const {
    double largest = !has_fluid() ? 0.0 : double(params.heat.fluid_diffusivity);
    for (const SceneObject& o : objects)
        if (o.kind != SolidKind::kStatic) largest = std::max(largest, double(o.thermal_diffusivity));
    return largest;
}

std::string heat_substeps_warning(int needed, int max_substeps) {
    if (needed <= max_substeps) return "";
    char text[300];
    std::snprintf(text, sizeof text,
                  "the largest step needs %d heat sub-steps, more than heat.max_substeps (%d): there the heat "
                  "spreads more slowly than the diffusivities say, and is conserved only approximately (docs/heat.md)",
                  needed, max_substeps);
    return text;
}

bool Scene::writes_vtu() const { return std::find(formats.begin(), formats.end(), "vtu") != formats.end(); }
bool Scene::writes_surface() const {
    return std::find(formats.begin(), formats.end(), "surface") != formats.end();
}

const char* default_scene_text() { return kDefaultScene; }

Scene resolve_scene(const SceneJson& raw, const std::string& source) {
    Scene scene;
    scene.source = source;
    SceneJson out;
    Section root(&raw, "", out, source);
    scene.name = root.string("name", "");
    // The name becomes the default output directory results/<name>: no path separators or dots
    // that would lead elsewhere, nothing a shell or a terminal would mangle.
    if (scene.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") !=
        std::string::npos)
        root.fail("name", "use letters, digits, '_' and '-' only (it names the output directory), got \"" +
                              scene.name + "\"");
    root.string("description", "");
    // 2D scenes are planned; until then any other value is refused.
    if (const double d = root.number("dimensions", 3.0, Range::any()); d != 3)
        root.fail("dimensions", "only 3 is supported for now, got " + format_number(d));
    out["dimensions"] = 3;
    read_domain(root.object("domain"), scene);
    scene.params.gravity = root.vec3("gravity", std::array<double, 3>{0, -9.81, 0});
    read_fluid(root.object("fluid"), scene);
    read_solver(root.object("solver"), scene);
    read_boundary(root.object("boundary"), scene);
    read_coupling(root.object("coupling"), scene);
    read_heat(root.object("heat"), scene);
    read_neighbors(root.object("neighbors"), scene);
    read_fluid_blocks(root, scene);
    read_static_boxes(root, scene);
    read_objects(root, scene);
    read_run(root.object("run"), scene);
    read_emitters(root, scene);
    if (scene.fluid_blocks.empty() && scene.objects.empty() && scene.emitters.empty()) {
        const std::string hint = root.misspelling_hint("fluid_blocks");
        root.fail("fluid_blocks", "at least one fluid block (or one object, or one emitter) is needed" +
                                      (hint.empty() ? root.misspelling_hint("objects") : hint));
    }
    read_output(root.object("output"), scene);
    root.finish();
    if (scene.writes_surface()) {
        // The surface's node box spans at most the domain and one support radius around it:
        // refuse now a voxel that could need more nodes than a frame may take.
        const double nodes =
            most_surface_nodes(scene.params, Real(scene.surface_voxel) * scene.params.fluid.spacing);
        if (nodes > double(kMaxSurfaceNodes)) {
            char count[32];
            std::snprintf(count, sizeof count, "%.3g", nodes);
            throw InputError(source + ": output.surface.voxel " + format_number(scene.surface_voxel) +
                             ": the surface over this domain could need " + count + " nodes, more than " +
                             std::to_string(kMaxSurfaceNodes) + " (2^28); raise it");
        }
    }
    scene.resolved = out;
    return scene;
}

Scene parse_scene_text(const std::string& text, const std::string& source, const std::vector<std::string>& overrides) {
    SceneJson raw;
    try {
        raw = parse_json_refusing_duplicates(text, source);
    } catch (const SceneJson::exception& e) {
        // nlohmann's message starts with "[json.exception.parse_error.101] parse error at line 3, column 5: ..."
        // (or out_of_range.406 "number overflow parsing '1e999'").
        std::string what = e.what();
        const auto bracket = what.find("] ");
        if (bracket != std::string::npos) what = what.substr(bracket + 2);
        throw InputError(source + ": malformed JSON: " + what);
    }
    if (!raw.is_object()) throw InputError(source + ": a scene must be a JSON object { ... }, got " + type_name(raw));
    Scene scene = resolve_scene(raw, source);
    // Overrides are checked together, not one by one: values that depend on each other (spacing
    // and support radius) may only be valid once both are set. Each key path is checked against
    // the last scene that resolved.
    bool resolved_last = true;
    for (const auto& o : overrides) {
        apply_override(raw, scene.resolved, o);
        try {
            scene = resolve_scene(raw, source);
            resolved_last = true;
        } catch (const InputError&) {
            resolved_last = false;  // a later --set may make it valid; the final check reports it
        }
    }
    if (!resolved_last) {
        try {
            scene = resolve_scene(raw, source);
        } catch (const InputError& e) {
            std::string list;
            for (const auto& o : overrides) list += (list.empty() ? "" : ", ") + std::string("--set ") + o;
            throw InputError(std::string(e.what()) + " (after " + list + ")");
        }
    }
    return scene;
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
    if (path.empty()) return parse_scene_text(default_scene_text(), "built-in default scene", overrides);
    Scene scene = parse_scene_text(read_file(path), path, overrides);
    scene.base_dir = std::filesystem::path(path).parent_path().string();
    // Mesh files are relative to the scene file's folder. The resolved scene (written into
    // summary.json) names them absolutely, so that it reproduces the run wherever it is saved.
    for (std::size_t k = 0; k < scene.objects.size(); ++k) {
        std::string& file = scene.objects[k].mesh_file;
        if (file.empty() || std::filesystem::path(file).is_absolute()) continue;
        std::error_code error;
        const std::filesystem::path absolute =
            std::filesystem::absolute(std::filesystem::path(scene.base_dir) / file, error).lexically_normal();
        if (error) continue;  // left relative; the mesh loader names the file if it cannot be read
        file = absolute.string();
        scene.resolved["objects"][k]["mesh"]["file"] = file;
    }
    return scene;
}

}  // namespace mw
