// The scene schema: the modules' key tables (algorithms/*_params.hpp) and the program's own
// (geometry, guards, run and output), read section by section into a Scene, with the checks that
// relate keys to one another.
#include "apps/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "apps/scene_json.hpp"
#include "apps/scene_section.hpp"
#include "common/errors.hpp"
#include "sampling/wall_gap.hpp"
#include "render/preview.hpp"
#include "surface/fluid_surface.hpp"

namespace mw {

namespace {

const char* kDefaultScene =
#include "default_scene.inc"
    ;

// ---- The program's own keys -----------------------------------------------------------------

// The preview camera that frames the domain read so far (render/preview.hpp's default_camera), for
// output.preview.width / height pictures; head-on in 2D.
struct DefaultView {
    Vec3 eye, target;
};
DefaultView default_view(const ResolvedKeys& r) {
    const ParamValue *lo = r.find("domain.min"), *hi = r.find("domain.max");
    const double width = r.number("output.preview.width"), height = r.number("output.preview.height");
    if (!lo || !hi || !(height > 0)) return {Vec3{0, 0, 1}, Vec3{0, 0, 0}};
    const PreviewCamera c = default_camera({lo->vector[0], lo->vector[1], lo->vector[2]},
                                           {hi->vector[0], hi->vector[1], hi->vector[2]}, width / height,
                                           r.dimensions == 2);
    const auto vec = [](const PreviewVec& v) { return Vec3{Real(v[0]), Real(v[1]), Real(v[2])}; };
    return {vec(c.eye), vec(c.target)};
}

const ParamTable<Scene>& scene_keys() {
    using T = Scene;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(text_key<T>("", "name", member(&T::name),
                                "letters, digits, _ and -: names the default output directory results/<name>"));
        t.push_back(text_key<T>("", "description", member(&T::description), "free text"));
        t.push_back(vector_key<T>("", "gravity", [](auto& s) -> auto& { return s.params.gravity; }, ParamRange::any(),
                                  "m/s2", "gravity"));
        t.push_back(vector_key<T>("domain", "min", [](auto& s) -> auto& { return s.params.domain_min; },
                                  ParamRange::any(), "m", "the simulation box's lower corner")
                        .must_be_given());
        t.push_back(vector_key<T>("domain", "max", [](auto& s) -> auto& { return s.params.domain_max; },
                                  ParamRange::any(), "m", "its upper corner (max > min on every axis)")
                        .must_be_given());
        t.push_back(number_key<T>("fluid", "temperature", member(&T::fluid_temperature), ParamRange::celsius(), "C",
                                  "the fluid blocks', emitters' and objects' default temperature, with heat.enabled"));
        t.push_back(number_key<T>("solver", "max_density_error", member(&T::max_density_error),
                                  ParamRange::positive(), "",
                                  "the run stops (exit 4) at a step that ends with a peak density error above it"));
        t.push_back(optional_number_key<T>("solver", "max_speed", member(&T::max_speed), ParamRange::positive(), "m/s",
                                           "the run stops (exit 4) at a step that ends with a particle faster; "
                                           "null: 20 times the scene's speed scale (docs/solver.md)"));
        t.push_back(number_key<T>("boundary", "spacing_factor", member(&T::boundary_spacing_factor),
                                  ParamRange{0, 1, true, false}, "", "boundary particle spacing, in r0"));
        t.push_back(integer_key<T>("boundary", "layers", member(&T::boundary_layers), 1, 8,
                                   "boundary layers of the domain walls (and the static boxes' default)"));
        t.push_back(number_key<T>("boundary", "max_lost_fraction", member(&T::max_lost_fraction),
                                  ParamRange{0, 1, false, false}, "",
                                  "the run stops (exit 4) once more than this share of the fluid has left the domain")
                        .derive_default([](const ResolvedKeys& r) {
                            return ParamValue::of(r.boolean("boundary.walls") ? 0.01 : 1.0);
                        }, "0.01 with walls, 1 without"));
        // 1e6 s keeps step counts in range.
        t.push_back(number_key<T>("run", "end_time", member(&T::end_time), ParamRange{0, 1e6, true, false}, "s",
                                  "simulated time to reach when neither --steps nor --time is given"));
        t.push_back(number_key<T>("output", "fps", member(&T::fps), ParamRange{0, 10000, true, false}, "1/s",
                                  "frames per simulated second, plus frame 0"));
        t.push_back(text_list_key<T>("output", "formats", member(&T::formats), {"vtu", "ply", "surface", "vdb", "preview"},
                                     "what each frame writes: particles (vtu, ply), the fluid's surface mesh (surface; "
                                     "in 2D its contour; as PLY too with ply), its level set and colour field (vdb, 3D), "
                                     "a picture (preview)"));
        t.push_back(number_key<T>("output.surface", "voxel", member(&T::surface_voxel), ParamRange{0.1, 4, false, false},
                                  "r0", "the surface field's node spacing"));
        t.push_back(integer_key<T>("output.preview", "width", [](auto& s) -> auto& { return s.preview.width; }, 16,
                                   8192, "the preview pictures' width, pixels"));
        t.push_back(integer_key<T>("output.preview", "height", [](auto& s) -> auto& { return s.preview.height; }, 16,
                                   8192, "their height, pixels"));
        t.push_back(choice_key<T, PreviewField>("output.preview", "field", [](auto& s) -> auto& { return s.preview.field; },
                                                {{"speed", PreviewField::kSpeed},
                                                 {"pressure", PreviewField::kPressure},
                                                 {"density", PreviewField::kDensity},
                                                 {"temperature", PreviewField::kTemperature}},
                                                "what colours the fluid particles (temperature: with heat.enabled)"));
        t.push_back(vector_key<T>("output.preview", "eye", [](auto& s) -> auto& { return s.preview.eye; },
                                  ParamRange::any(), "m", "where the camera stands")
                        .derive_default([](const ResolvedKeys& r) { return ParamValue::of(default_view(r).eye); },
                                        "a three-quarter view from above and in front that frames the domain"));
        t.push_back(vector_key<T>("output.preview", "target", [](auto& s) -> auto& { return s.preview.target; },
                                  ParamRange::any(), "m", "the point it looks at (differs from eye)")
                        .derive_default([](const ResolvedKeys& r) { return ParamValue::of(default_view(r).target); },
                                        "the domain's middle, as framed"));
        t.push_back(number_key<T>("output.preview", "fov", [](auto& s) -> auto& { return s.preview.fov; },
                                  ParamRange{1, 170, false, false}, "degrees", "the vertical field of view"));
        return t;
    }();
    return table;
}

const ParamTable<FluidBlock>& block_keys() {
    using T = FluidBlock;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(vector_key<T>("fluid_blocks[]", "min", member(&T::min), ParamRange::any(), "m",
                                  "the block's lower corner; particles sit at min + (k + 1/2) r0")
                        .must_be_given());
        t.push_back(vector_key<T>("fluid_blocks[]", "max", member(&T::max), ParamRange::any(), "m",
                                  "its upper corner: inside the domain, clear of the other blocks")
                        .must_be_given());
        t.push_back(vector_key<T>("fluid_blocks[]", "velocity", member(&T::velocity), ParamRange::any(), "m/s",
                                  "initial velocity"));
        t.push_back(number_key<T>("fluid_blocks[]", "temperature", member(&T::temperature), ParamRange::celsius(), "C",
                                  "initial temperature, with heat.enabled")
                        .derive_default([](const ResolvedKeys& r) { return *r.find("fluid.temperature"); },
                                        "fluid.temperature"));
        return t;
    }();
    return table;
}

const ParamTable<StaticBox>& box_keys() {
    using T = StaticBox;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(vector_key<T>("static_boxes[]", "min", member(&T::min), ParamRange::any(), "m",
                                  "the box's lower corner").must_be_given());
        t.push_back(vector_key<T>("static_boxes[]", "max", member(&T::max), ParamRange::any(), "m",
                                  "its upper corner: inside the domain").must_be_given());
        t.push_back(integer_key<T>("static_boxes[]", "layers", member(&T::layers), 1, 8,
                                   "boundary layers (the first on the faces, more inside)")
                        .derive_default([](const ResolvedKeys& r) { return *r.find("boundary.layers"); },
                                        "boundary.layers"));
        return t;
    }();
    return table;
}

const ParamTable<SceneObject>& object_keys() {
    using T = SceneObject;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(text_key<T>("objects[].mesh", "file", member(&T::mesh_file),
                                "an OBJ file (in 2D an outline file), relative to the scene file (the shipped meshes: ../shared/assets/meshes)"));
        t.push_back(text_key<T>("objects[].mesh", "procedural", member(&T::mesh_procedural),
                                "or a procedural mesh: box:x=,y=,z= or sphere:radius= (docs/sampling.md); a rod's line:length= (docs/rods.md); "
                                "in 2D an outline: rectangle:x=,y=, circle:radius= (docs/scenes.md)"));
        t.push_back(vector_key<T>("objects[].transform", "scale", member(&T::scale), ParamRange::any(), "",
                                  "applied first; non-zero on every axis"));
        t.push_back(vector_key<T>("objects[].transform", "rotation_deg", member(&T::rotation_deg), ParamRange::any(),
                                  "degrees", "about x, then y, then z"));
        t.push_back(vector_key<T>("objects[].transform", "translation", member(&T::translation), ParamRange::any(),
                                  "m", "applied last"));
        t.push_back(vector_key<T>("objects[]", "velocity", member(&T::velocity), ParamRange::any(), "m/s",
                                  "initial velocity"));
        t.push_back(number_key<T>("objects[]", "surface_spacing", member(&T::surface_spacing),
                                  ParamRange{0.25, 1, false, false}, "r0",
                                  "an elastic or rigid object's surface particles at most this far apart; below 1 "
                                  "the denser boundary a method without the correction needs (docs/coupling.md)"));
        t.push_back(number_key<T>("objects[]", "temperature", member(&T::temperature), ParamRange::celsius(), "C",
                                  "initial temperature, with heat.enabled")
                        .derive_default([](const ResolvedKeys& r) { return *r.find("fluid.temperature"); },
                                        "fluid.temperature"));
        t.push_back(vector_key<T>("objects[].pinned.box", "min", member(&T::pin_min), ParamRange::any(), "m",
                                  "inner particles inside the box [min, max] stay at rest").must_be_given());
        t.push_back(vector_key<T>("objects[].pinned.box", "max", member(&T::pin_max), ParamRange::any(), "m",
                                  "its upper corner").must_be_given());
        t.push_back(vector_key<T>("objects[].pinned.boxes[]", "min", member(&T::pin_min), ParamRange::any(), "m",
                                  "or several boxes: inner particles inside any of them stay at rest (a cloth's "
                                  "corners)").must_be_given());
        t.push_back(vector_key<T>("objects[].pinned.boxes[]", "max", member(&T::pin_max), ParamRange::any(), "m",
                                  "its upper corner").must_be_given());
        t.push_back(vector_key<T>("objects[].pinned.half_space", "point", member(&T::pin_point), ParamRange::any(), "m",
                                  "inner particles with (x - point).normal < 0 stay at rest (or give box)")
                        .must_be_given());
        t.push_back(vector_key<T>("objects[].pinned.half_space", "normal", member(&T::pin_normal), ParamRange::any(),
                                  "", "not zero").must_be_given());
        return t;
    }();
    return table;
}

// Keys read by hand (their checks relate them to other keys), documented here beside the tables.
std::vector<ParamDoc> keys_read_by_hand() {
    return {
        {"dimensions", "integer", "3", "2 or 3", "",
         "2: particles in the plane z = 0, vectors [x, y], objects from outlines (docs/scenes.md)"},
        {"objects[].name", "string", "\"object<i>\"", "letters, digits, _ and -; unique", "",
         "names the object's output files"},
        {"emitters[].name", "string", "\"emitter<i>\"", "letters, digits, _ and -; unique", "", "names it in info"},
        {"pressure_sensors[].name", "string", "\"sensor<i>\"", "letters, digits, _ and -; unique", "",
         "its stats.csv column is sensor_<name>, in Pa"},
    };
}

// ---- Checks that relate keys ----------------------------------------------------------------

}  // namespace

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

namespace {

// A 2D scene's boxes are rectangles in the plane z = 0.
void check_box(const Section& s, Vec3 lo, Vec3 hi, int dimensions = 3) {
    if (!(hi.x > lo.x && hi.y > lo.y && (dimensions == 2 || hi.z > lo.z)))
        s.fail(s.key_path("max"), "must exceed min on every axis");
}

// In 2D only x and y: a z off the plane gets check_plane()'s message.
bool inside(Vec3 lo, Vec3 hi, Vec3 dlo, Vec3 dhi, int dimensions) {
    const Real eps = Real(1e-6);
    const bool inside_z = dimensions == 2 || (lo.z >= dlo.z - eps && hi.z <= dhi.z + eps);
    return lo.x >= dlo.x - eps && lo.y >= dlo.y - eps && hi.x <= dhi.x + eps && hi.y <= dhi.y + eps && inside_z;
}

void check_inside_domain(const Section& s, const Scene& scene, Vec3 lo, Vec3 hi, const char* what) {
    if (!inside(lo, hi, scene.params.domain_min, scene.params.domain_max, scene.params.dimensions))
        s.fail(s.path(), std::string("the ") + what + " must lie inside the domain " +
                             describe_box(scene.params.domain_min, scene.params.domain_max));
}

// Refuses a block [lo, hi] that shares volume with a fluid block read so far (touching faces do
// not count): two lattices in one place have a density far above rest that PCISPH resolves by an
// explosion. (Static boxes and objects may overlap the fluid: build_setup carves it out.)
void check_clear_of_fluid_blocks(const Section& s, const Scene& scene, Vec3 lo, Vec3 hi) {
    for (std::size_t k = 0; k < scene.fluid_blocks.size(); ++k) {
        const FluidBlock& f = scene.fluid_blocks[k];
        const bool overlap_z = scene.params.dimensions == 2 || (lo.z < f.max.z && f.min.z < hi.z);
        if (lo.x < f.max.x && f.min.x < hi.x && lo.y < f.max.y && f.min.y < hi.y && overlap_z)
            s.fail(s.path(), "overlaps fluid_blocks[" + std::to_string(k) + "] " + describe_box(f.min, f.max) +
                                 "; blocks may touch but not overlap");
    }
}

// `name` of an object or emitter: letters, digits, '_' and '-' only, `fallback` when absent, and
// none of the names in `taken` (what `plural` lists so far).
template <class Named>
std::string read_unique_name(Section& s, const std::string& fallback, const std::vector<Named>& taken,
                             const std::string& plural, const std::string& why) {
    const SceneJson* v = s.find("name");
    std::string name = fallback;
    if (v) {
        if (!v->is_string()) s.fail(s.key_path("name"), "expected a string, got " + json_type_name(*v));
        name = v->get<std::string>();
    }
    if (name.empty() ||
        name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") != std::string::npos)
        s.fail(s.key_path("name"), "use letters, digits, '_' and '-' only" + why + ", got \"" + name + "\"");
    for (const Named& other : taken)
        if (other.name == name) s.fail(s.key_path("name"), "two " + plural + " are named \"" + name + "\"");
    s.record("name", name);
    return name;
}

// ---- One function per section -----------------------------------------------------------------

void read_root(Section& root, Scene& scene) {
    // First: a 2D scene's vectors, the root's own among them, are read as [x, y].
    if (const SceneJson* d = root.find("dimensions")) {
        if (!d->is_number()) root.fail("dimensions", "expected a number, got " + json_type_name(*d));
        const double value = d->get<double>();
        if (value != 2 && value != 3) root.fail("dimensions", "expected 2 or 3, got " + format_scene_number(value));
        scene.params.dimensions = static_cast<int>(value);
    }
    root.resolved().dimensions = scene.params.dimensions;
    root.record("dimensions", scene.params.dimensions);
    root.read(scene_keys(), scene);
    // The name becomes the default output directory results/<name>: no path separators or dots
    // that would lead elsewhere, nothing a shell or a terminal would mangle.
    if (scene.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") !=
        std::string::npos)
        root.fail("name", "use letters, digits, '_' and '-' only (it names the output directory), got \"" +
                              scene.name + "\"");
}

void read_domain(Section s, Scene& scene) {
    s.read(scene_keys(), scene);
    check_box(s, scene.params.domain_min, scene.params.domain_max, scene.params.dimensions);
    s.finish();
}

void read_fluid(Section s, Scene& scene) {
    s.read(fluid_keys(), scene.params.fluid);
    s.read(scene_keys(), scene);
    s.read(heat_keys(), scene.params.heat);
    s.finish();
}

void read_solver(Section s, Scene& scene) {
    SolverParams& p = scene.params.solver;
    s.read(solver_keys(), p);
    if (p.max_iterations < p.min_iterations)
        s.fail(s.key_path("max_iterations"), "must be >= min_iterations (" + std::to_string(p.min_iterations) +
                                                 "), got " + std::to_string(p.max_iterations));
    if (p.shorten_above_iterations != 0 && p.shorten_above_iterations < p.min_iterations)
        s.fail(s.key_path("shorten_above_iterations"), "must be 0 (off) or >= min_iterations (" +
                                                           std::to_string(p.min_iterations) + "), got " +
                                                           std::to_string(p.shorten_above_iterations));
    s.read(scene_keys(), scene);
    s.finish();
}

// Sections whose keys are one module's table (and the program's, for `boundary`).
template <class T>
void read_module(Section s, Scene& scene, const ParamTable<T>& table, T& target) {
    s.read(table, target);
    s.read(scene_keys(), scene);
    s.finish();
}

void read_fluid_blocks(Section& root, Scene& scene) {
    root.array_of_objects("fluid_blocks", [&](Section& s, int) {
        FluidBlock b;
        s.read(block_keys(), b);
        check_box(s, b.min, b.max, scene.params.dimensions);
        check_inside_domain(s, scene, b.min, b.max, "block");
        check_clear_of_fluid_blocks(s, scene, b.min, b.max);
        scene.fluid_blocks.push_back(b);
    });
}

void read_static_boxes(Section& root, Scene& scene) {
    root.array_of_objects("static_boxes", [&](Section& s, int) {
        StaticBox b;
        s.read(box_keys(), b);
        check_box(s, b.min, b.max, scene.params.dimensions);
        check_inside_domain(s, scene, b.min, b.max, "box");
        scene.static_boxes.push_back(b);
    });
}

void read_object_pinned(Section s, SceneObject& o, int dimensions) {
    const bool has_box = s.find("box") != nullptr, has_boxes = s.find("boxes") != nullptr,
               has_half = s.find("half_space") != nullptr;
    if (int(has_box) + int(has_boxes) + int(has_half) > 1)
        s.fail(s.path(), "give one of \"box\", \"boxes\" or \"half_space\"");
    if (has_box) {
        Section b = s.object("box");
        o.pin = SceneObject::Pin::kBoxes;
        b.read(object_keys(), o);
        check_box(b, o.pin_min, o.pin_max, dimensions);
        o.pin_boxes.emplace_back(o.pin_min, o.pin_max);
        b.finish();
    }
    if (has_boxes) {
        o.pin = SceneObject::Pin::kBoxes;
        s.array_of_objects("boxes", [&](Section& b, int) {
            b.read(object_keys(), o);
            check_box(b, o.pin_min, o.pin_max, dimensions);
            o.pin_boxes.emplace_back(o.pin_min, o.pin_max);
        });
        if (o.pin_boxes.empty()) s.fail(s.key_path("boxes"), "must hold at least one box");
    }
    if (has_half) {
        Section h = s.object("half_space");
        o.pin = SceneObject::Pin::kHalfSpace;
        h.read(object_keys(), o);
        if (!(norm(o.pin_normal) > 0)) h.fail(h.key_path("normal"), "must be non-zero");
        h.finish();
    }
    s.finish();
}

// A 2D object is an outline in the plane z = 0 (or a rod's line there), moved and turned in it:
// elastic, rigid, static or rod. A cloth is a surface: the plane's sheet is a rod.
void check_object_in_plane(Section& s, const SceneObject& o, const char* kind) {
    if (o.kind == SolidKind::kCloth)
        s.fail(s.key_path("kind"), std::string("a 2D scene's objects are elastic, rigid, static or rod (this one is ") +
                                       kind + "; a rod is the plane's sheet)");
    const auto in_plane = [&](const char* key, Vec3 v) {
        if (v.z != 0) s.fail(s.key_path(key), describe_point(v) + ": a 2D scene lies in the plane z = 0; give [x, y]");
    };
    in_plane("transform.translation", o.translation);
    in_plane("velocity", o.velocity);
    if (o.rotation_deg.x != 0 || o.rotation_deg.y != 0)
        s.fail(s.key_path("transform.rotation_deg"),
               describe_point(o.rotation_deg) + ": a 2D object turns in its plane only; give [0, 0, angle]");
    if (o.pin == SceneObject::Pin::kHalfSpace) in_plane("pinned.half_space.normal", o.pin_normal);
}

void read_object(Section& s, int index, Scene& scene) {
    SceneObject o;
    o.name = read_unique_name(s, "object" + std::to_string(index), scene.objects, "objects", " (it names output files)");
    Section mesh = s.object("mesh");
    mesh.read(object_keys(), o);
    if (o.mesh_file.empty() == o.mesh_procedural.empty())
        mesh.fail(mesh.path(), "give exactly one of \"file\" (an OBJ file) or \"procedural\" (e.g. \"sphere:radius=0.1\")" +
                                   mesh.misspelling_hint(o.mesh_file.empty() ? "file" : "procedural"));
    mesh.finish();
    Section transform = s.object("transform");
    transform.read(object_keys(), o);
    if (scene.params.dimensions == 2) o.scale.z = 1;  // [x, y]: the outline lies in z = 0
    if (o.scale.x == 0 || o.scale.y == 0 || o.scale.z == 0)
        transform.fail(transform.key_path("scale"), "must be non-zero on every axis");
    transform.finish();
    s.read(object_keys(), o);
    s.read(solid_keys(), static_cast<SolidParams&>(o));
    const char* kind = o.kind == SolidKind::kRigid    ? "rigid"
                       : o.kind == SolidKind::kStatic ? "static"
                       : o.kind == SolidKind::kCloth  ? "cloth"
                       : o.kind == SolidKind::kRod    ? "rod"
                                                      : "elastic";
    if (o.kind == SolidKind::kStatic && o.interface_tension > 0)
        s.fail(s.key_path("interface_tension"), "is for elastic, rigid and cloth objects (this one is static)");
    // Melting (docs/melting.md): an elastic object in a scene that conducts heat.
    if (o.melts() && o.kind != SolidKind::kElastic)
        s.fail(s.key_path("melting_point"), std::string("is for elastic objects (this one is ") + kind + ")");
    if (is_thin(o.kind) && scene.params.heat.enabled)
        s.fail(s.key_path("kind"), std::string(kind) + " does not conduct heat: set heat.enabled to false, or make it elastic");
    if (o.melts() && !scene.params.heat.enabled)
        s.fail(s.key_path("melting_point"), "needs heat conduction: set heat.enabled to true");
    if (o.latent_heat > 0 && !o.melts()) s.fail(s.key_path("latent_heat"), "needs a melting_point");
    if (o.surface_spacing != 1 && ((o.kind != SolidKind::kElastic && o.kind != SolidKind::kRigid) || o.melts()))
        s.fail(s.key_path("surface_spacing"),
               std::string("is for elastic and rigid objects that do not melt (this one is ") + kind + ")");
    Section lsm = s.object("lsm");
    lsm.read(solid_keys(), static_cast<SolidParams&>(o));
    lsm.finish();
    read_object_pinned(s.object("pinned"), o, scene.params.dimensions);
    if (scene.params.dimensions == 2) check_object_in_plane(s, o, kind);
    scene.objects.push_back(o);
}

// The disc's particles start r0/2 inside the domain at the most, as a fluid block's do.
void check_emitter_disc(const Section& s, const Scene& scene, const SceneEmitter& e, double radius) {
    const double margin = 0.5 * double(scene.params.fluid.spacing) * (1 - 1e-6);
    const Vec3 lo = scene.params.domain_min, hi = scene.params.domain_max;
    const double n[3] = {e.direction.x, e.direction.y, e.direction.z}, c[3] = {e.center.x, e.center.y, e.center.z},
                 low[3] = {lo.x, lo.y, lo.z}, high[3] = {hi.x, hi.y, hi.z};
    for (int a = 0; a < scene.params.dimensions; ++a) {  // in 2D a segment in the plane
        // How far the disc reaches along axis a: radius x sin(angle between the axis and its normal).
        const double extent = radius * std::sqrt(std::max(0.0, 1 - n[a] * n[a]));
        if (c[a] - extent < low[a] + margin || c[a] + extent > high[a] - margin)
            s.fail(s.path(), "the disc (center " + describe_point(e.center) + ", radius " + format_scene_number(radius) +
                                 ") must lie inside the domain " + describe_box(lo, hi) + ", r0/2 from its faces");
    }
}

// After `run`: an emitter's end defaults to the run's.
void read_emitters(Section& root, Scene& scene) {
    root.array_of_objects("emitters", [&](Section& s, int index) {
        if (std::size_t(index) >= kMaxEmitters)
            s.fail(s.path(), "at most " + std::to_string(kMaxEmitters) + " emitters are supported");
        SceneEmitter e;
        e.name = read_unique_name(s, "emitter" + std::to_string(index), scene.emitters, "emitters", "");
        s.read(emitter_keys(), static_cast<EmitterParams&>(e));
        if (!(norm(e.direction) > 0)) s.fail(s.key_path("direction"), "must not be zero");
        e.direction = (Real(1) / norm(e.direction)) * e.direction;
        if (!(e.end > e.start))
            s.fail(s.key_path("end"), "must be later than start (" + format_scene_number(e.start) + " s), got " +
                                          format_scene_number(e.end));
        check_emitter_disc(s, scene, e, s.resolved().number("emitters[].radius"));
        scene.emitters.push_back(e);
    });
}

// A sensor sits on the domain face nearest its centre, within r0/2 of it, and its patch lies
// within that face; in 2D the faces are the domain's four sides, the patch a segment of one.
void read_pressure_sensors(Section& root, Scene& scene) {
    root.array_of_objects("pressure_sensors", [&](Section& s, int index) {
        if (index >= 64) s.fail(s.path(), "at most 64 pressure sensors are supported");
        PressureSensorSetup p;
        p.name = read_unique_name(s, "sensor" + std::to_string(index), scene.pressure_sensors, "pressure sensors", "");
        s.read(pressure_sensor_keys(), static_cast<PressureSensorParams&>(p));
        const Vec3 lo = scene.params.domain_min, hi = scene.params.domain_max;
        const double c[3] = {p.center.x, p.center.y, p.center.z}, low[3] = {lo.x, lo.y, lo.z},
                     high[3] = {hi.x, hi.y, hi.z};
        const int axes = scene.params.dimensions;
        double nearest = 1e300;
        for (int a = 0; a < axes; ++a)
            for (int side : {-1, 1}) {
                const double distance = std::abs(c[a] - (side < 0 ? low[a] : high[a]));
                if (distance < nearest) {
                    nearest = distance;
                    p.axis = a;
                    p.side = side;
                }
            }
        const double r0 = double(scene.params.fluid.spacing);
        if (nearest > 0.5 * r0 * (1 + 1e-6))
            s.fail(s.key_path("center"), "must lie on a face of the domain " + describe_box(lo, hi) +
                                             " (within r0/2 of it): " + describe_point(p.center) + " is " +
                                             format_scene_number(nearest) + " m from the nearest");
        const double half = 0.5 * double(p.size);
        for (int a = 0; a < axes; ++a)
            if (a != p.axis && (c[a] - half < low[a] - 1e-9 || c[a] + half > high[a] + 1e-9))
                s.fail(s.key_path("size"), "the patch (centre " + describe_point(p.center) + ", side " +
                                               format_scene_number(double(p.size)) + ") reaches past its face of the domain " +
                                               describe_box(lo, hi));
        scene.pressure_sensors.push_back(p);
    });
}

void read_output(Section s, Scene& scene) {
    s.read(scene_keys(), scene);
    for (const char* part : {"surface", "preview"}) {
        Section sub = s.object(part);
        sub.read(scene_keys(), scene);
        sub.finish();
    }
    s.finish();
}

// The surface's node box spans at most the domain and one support radius around it: a voxel that
// could need more nodes than a frame may take is refused now.
void check_surface_voxel(const Scene& scene) {
    if (!scene.frame_formats().color_field()) return;
    const double nodes = most_surface_nodes(scene.params, Real(scene.surface_voxel) * scene.params.fluid.spacing);
    if (nodes > double(kMaxSurfaceNodes)) {
        char count[32];
        std::snprintf(count, sizeof count, "%.3g", nodes);
        throw InputError(scene.source + ": output.surface.voxel " + format_scene_number(scene.surface_voxel) +
                         ": the surface over this domain could need " + count + " nodes, more than " +
                         std::to_string(kMaxSurfaceNodes) + " (2^28); raise it");
    }
}

// A 2D scene lies in the plane z = 0: its domain, blocks, boxes, emitters and gravity have no z,
// and its frames are particles and pictures (the surface is a 3D mesh).
void check_plane(const Scene& scene) {
    if (scene.params.dimensions != 2) return;
    const auto off_plane = [&](const std::string& key, Vec3 v) {
        if (v.z != 0)
            throw InputError(scene.source + ": " + key + " " + describe_point(v) +
                             ": a 2D scene lies in the plane z = 0; give [x, y]");
    };
    off_plane("domain.min", scene.params.domain_min);
    off_plane("domain.max", scene.params.domain_max);
    off_plane("gravity", scene.params.gravity);
    for (std::size_t i = 0; i < scene.fluid_blocks.size(); ++i) {
        const std::string key = "fluid_blocks[" + std::to_string(i) + "]";
        off_plane(key + ".min", scene.fluid_blocks[i].min);
        off_plane(key + ".max", scene.fluid_blocks[i].max);
        off_plane(key + ".velocity", scene.fluid_blocks[i].velocity);
    }
    for (std::size_t i = 0; i < scene.emitters.size(); ++i) {
        const std::string key = "emitters[" + std::to_string(i) + "]";
        off_plane(key + ".center", scene.emitters[i].center);
        off_plane(key + ".direction", scene.emitters[i].direction);
    }
    for (std::size_t i = 0; i < scene.static_boxes.size(); ++i) {
        const std::string key = "static_boxes[" + std::to_string(i) + "]";
        off_plane(key + ".min", scene.static_boxes[i].min);
        off_plane(key + ".max", scene.static_boxes[i].max);
    }
    const FrameFormats f = scene.frame_formats();
    if (f.vdb)
        throw InputError(scene.source + ": output.formats: \"vdb\" is a 3D output (volumes); a 2D scene writes vtu, ply, "
                         "surface (the fluid's contour) and preview frames");
}

// The preview's camera must look somewhere, and temperature colours only what heat conduction gives one.
void check_preview(const Scene& scene) {
    const Vec3 d = scene.preview.target - scene.preview.eye;
    if (!(d.x * d.x + d.y * d.y + d.z * d.z > 0))
        throw InputError(scene.source + ": output.preview.target must differ from output.preview.eye");
    if (scene.preview.field == PreviewField::kTemperature && !scene.params.heat.enabled)
        throw InputError(scene.source + ": output.preview.field \"temperature\" needs heat.enabled true");
}

// The rows of `table` in `section`.
template <class T>
void add_rows(std::vector<ParamDoc>& rows, const ParamTable<T>& table, const std::string& section) {
    ParamTable<T> in_section;
    for (const ParamKey<T>& k : table)
        if (section == k.section) in_section.push_back(k);
    const std::vector<ParamDoc> docs = param_docs(in_section);
    rows.insert(rows.end(), docs.begin(), docs.end());
}

}  // namespace

std::vector<ParamDoc> scene_schema() {
    std::vector<ParamDoc> rows;
    const std::vector<ParamDoc> by_hand = keys_read_by_hand();
    add_rows(rows, scene_keys(), "");
    rows.push_back(by_hand[0]);
    add_rows(rows, scene_keys(), "domain");
    add_rows(rows, fluid_keys(), "fluid");
    add_rows(rows, scene_keys(), "fluid");
    add_rows(rows, heat_keys(), "fluid");
    add_rows(rows, solver_keys(), "solver");
    add_rows(rows, scene_keys(), "solver");
    add_rows(rows, boundary_keys(), "boundary");
    add_rows(rows, scene_keys(), "boundary");
    add_rows(rows, coupling_keys(), "coupling");
    add_rows(rows, heat_keys(), "heat");
    add_rows(rows, neighbor_keys(), "neighbors");
    add_rows(rows, block_keys(), "fluid_blocks[]");
    add_rows(rows, box_keys(), "static_boxes[]");
    rows.push_back(by_hand[1]);
    for (const char* section : {"objects[].mesh", "objects[].transform", "objects[]"}) add_rows(rows, object_keys(), section);
    add_rows(rows, solid_keys(), "objects[]");
    add_rows(rows, solid_keys(), "objects[].lsm");
    for (const char* section : {"objects[].pinned.box", "objects[].pinned.boxes[]", "objects[].pinned.half_space"})
        add_rows(rows, object_keys(), section);
    add_rows(rows, scene_keys(), "run");
    rows.push_back(by_hand[2]);
    add_rows(rows, emitter_keys(), "emitters[]");
    rows.push_back(by_hand[3]);
    add_rows(rows, pressure_sensor_keys(), "pressure_sensors[]");
    add_rows(rows, scene_keys(), "output");
    add_rows(rows, scene_keys(), "output.surface");
    add_rows(rows, scene_keys(), "output.preview");
    return rows;
}

Real Scene::wall_gap() const {
    return rest_density_wall_gap(params.fluid.spacing, params.fluid.support_radius, boundary_spacing(),
                                 boundary_layers, params.fluid.kernel, params.dimensions);
}

std::string Scene::kernel_warning() const {
    const FluidParams& f = params.fluid;
    const double width = double(f.support_radius) / double(f.spacing);
    if (f.kernel != KernelKind::kCubicSpline || width <= 2.25 + 1e-6) return "";
    char text[400];
    std::snprintf(text, sizeof text,
                  "fluid.kernel \"cubic_spline\" with h = %.3g r0: wider than 2.25 r0 the cubic spline risks the "
                  "pairing instability (at 2.5 r0 the default dam break throws a particle at 30 m/s within 30 ms); "
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

FrameFormats Scene::frame_formats() const {
    const auto has = [this](const char* name) { return std::find(formats.begin(), formats.end(), name) != formats.end(); };
    FrameFormats f;
    f.vtu = has("vtu"), f.ply = has("ply"), f.surface = has("surface"), f.vdb = has("vdb"), f.preview = has("preview");
    return f;
}

const char* default_scene_text() { return kDefaultScene; }

Scene resolve_scene(const SceneJson& raw, const std::string& source) {
    Scene scene;
    scene.source = source;
    SceneJson out;
    ResolvedKeys resolved;
    Section root(&raw, "", "", out, source, resolved);
    read_root(root, scene);
    read_domain(root.object("domain"), scene);
    read_fluid(root.object("fluid"), scene);
    read_solver(root.object("solver"), scene);
    read_module(root.object("boundary"), scene, boundary_keys(), scene.params.boundary);
    read_module(root.object("coupling"), scene, coupling_keys(), scene.params.coupling);
    read_module(root.object("heat"), scene, heat_keys(), scene.params.heat);
    read_module(root.object("neighbors"), scene, neighbor_keys(), scene.params.neighbors);
    read_fluid_blocks(root, scene);
    read_static_boxes(root, scene);
    root.array_of_objects("objects", [&](Section& s, int index) { read_object(s, index, scene); });
    read_module(root.object("run"), scene, scene_keys(), scene);
    read_emitters(root, scene);
    read_pressure_sensors(root, scene);
    if (scene.fluid_blocks.empty() && scene.objects.empty() && scene.emitters.empty()) {
        const std::string hint = root.misspelling_hint("fluid_blocks");
        root.fail("fluid_blocks", "at least one fluid block (or one object, or one emitter) is needed" +
                                      (hint.empty() ? root.misspelling_hint("objects") : hint));
    }
    read_output(root.object("output"), scene);
    root.finish();
    check_plane(scene);
    check_surface_voxel(scene);
    check_preview(scene);
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
    if (!raw.is_object())
        throw InputError(source + ": a scene must be a JSON object { ... }, got " + json_type_name(raw));
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
    Scene scene = parse_scene_text(read_scene_file(path), path, overrides);
    scene.base_dir = std::filesystem::path(path).parent_path().string();
    // Mesh files are relative to the scene file's folder. The resolved scene (written into
    // summary.json) names them absolutely, so that it reproduces the run wherever it is saved.
    for (std::size_t k = 0; k < scene.objects.size(); ++k) {
        std::string& file = scene.objects[k].mesh_file;
        scene.objects[k].mesh_file_given = file;
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
