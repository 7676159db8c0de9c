#include "apps/scene_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "algorithms/lsm_regions.hpp"
#include "algorithms/solid_face.hpp"
#include "common/errors.hpp"
#include "sampling/box_particles.hpp"
#include "sampling/disc_lattice.hpp"
#include "sampling/inside_outside.hpp"
#include "sampling/kdtree.hpp"
#include "sampling/obj_loader.hpp"
#include "sampling/outline.hpp"
#include "sampling/outline_sample.hpp"
#include "sampling/outline_distance.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling/signed_distance.hpp"
#include "sampling/rod_sample.hpp"
#include "sampling/sheet_sample.hpp"
#include "sampling/solid_sample.hpp"
#include "sampling/surface_inset.hpp"
#include "sampling/wall_gap.hpp"

#include <filesystem>

namespace mw {

namespace {
// 2D boxes are rectangles: their lattice is one layer, their surface an outline.
double lattice_count(Vec3 lo, Vec3 hi, double spacing, int dimensions = 3) {
    const double layers_z = dimensions == 2 ? 1.0 : std::floor((hi.z - lo.z) / spacing + 1e-4);
    return std::floor((hi.x - lo.x) / spacing + 1e-4) * std::floor((hi.y - lo.y) / spacing + 1e-4) * layers_z;
}
double surface_count(Vec3 lo, Vec3 hi, double spacing, int layers, int dimensions = 3) {
    const double a = hi.x - lo.x + 2 * layers * spacing, b = hi.y - lo.y + 2 * layers * spacing,
                 c = hi.z - lo.z + 2 * layers * spacing;
    if (dimensions == 2) return layers * 2 * (a + b) / spacing + 4;
    return layers * 2 * (a * b + b * c + a * c) / (spacing * spacing) + 8;
}
void append(SimulationSetup& s, const std::vector<Vec3>& points, Vec3 velocity, std::uint8_t type, std::int32_t object) {
    for (const Vec3& p : points) {
        s.position.push_back(p);
        s.velocity.push_back(velocity);
        s.type.push_back(type);
        s.object.push_back(object);
    }
}

// Fluid blocks and static boxes are checked against the domain when the scene is read; an
// object's extent is known only once its mesh is loaded and transformed. Outside the domain its
// particles would be clamped onto the walls in the first step. A mesh touching a face may
// overshoot it by rounding (OBJ coordinates are read as float): a thousandth of r0 is allowed.
void check_object_inside_domain(const Scene& scene, const Aabb& box) {
    const double slack = 1e-3 * scene.params.fluid.spacing;
    const Vec3 lo = scene.params.domain_min, hi = scene.params.domain_max;
    if (box.lo.x() < lo.x - slack || box.lo.y() < lo.y - slack || box.lo.z() < lo.z - slack ||
        box.hi.x() > hi.x + slack || box.hi.y() > hi.y + slack || box.hi.z() > hi.z + slack) {
        char text[320];
        std::snprintf(text, sizeof text,
                      "the transformed mesh spans [%g, %g] x [%g, %g] x [%g, %g], not inside the domain "
                      "[%g, %g] x [%g, %g] x [%g, %g] (see transform)",
                      box.lo.x(), box.hi.x(), box.lo.y(), box.hi.y(), box.lo.z(), box.hi.z(), double(lo.x),
                      double(hi.x), double(lo.y), double(hi.y), double(lo.z), double(hi.z));
        throw InputError(text);
    }
}

// Refused before sampling, which would allocate per lattice point: inner particles about
// volume / r0³, surface particles about area / r0², plus the mesh's vertices.
void check_object_particle_budget(const Scene& scene, const TriangleMesh& mesh, std::size_t existing) {
    const double r0 = scene.params.fluid.spacing;
    // An outline: its IBPs, and along its perimeter at most 4 SBPs (surface_spacing 0.25) and 1 GP an r0.
    const bool outline = scene.params.dimensions == 2 && is_outline(mesh);
    const double total = outline ? double(existing) + outline_area(mesh) / (r0 * r0) +
                                                5 * outline_perimeter(mesh) / r0 + double(mesh.vertex_count())
                                          : double(existing) + std::fabs(signed_volume(mesh)) / (r0 * r0 * r0) +
                                                surface_area(mesh) / (r0 * r0) + double(mesh.vertex_count());
    if (total > double(kMaxSceneParticles))
        throw InputError("the scene would create about " + std::to_string(static_cast<long>(std::min(1e18, total))) +
                         " particles with this object (more than " + std::to_string(kMaxSceneParticles) +
                         "); increase fluid.spacing or scale the object down");
}

// An object as placed in the scene, for the overlap check: its mesh and its inner particles.
struct PlacedObject {
    TriangleMesh mesh;
    Eigen::AlignedBox3d bounds;
    std::vector<Vec3d> inner;  // IBP positions (inner lattice points for a static object)
    bool moves = false;        // elastic or rigid; static objects never move
    bool sheet = false;        // a cloth or a rod: nothing lies inside it
};

bool inside_box(Vec3 x, Vec3 lo, Vec3 hi) {
    return x.x >= lo.x && x.y >= lo.y && x.z >= lo.z && x.x <= hi.x && x.y <= hi.y && x.z <= hi.z;
}

// A pin that holds none of the object's inner particles (nodes) is a mistake in the scene:
// refused, naming the box. `inner`: the object's IBPs, at [first, first + inner) of the setup.
void check_pins_hold(const SceneObject& o, const SimulationSetup& setup, std::size_t first, std::size_t inner) {
    for (std::size_t b = 0; b < o.pin_boxes.size(); ++b) {
        const auto& box = o.pin_boxes[b];
        bool holds = false;
        for (std::size_t i = first; i < first + inner && !holds; ++i) holds = inside_box(setup.position[i], box.first, box.second);
        if (!holds)
            throw InputError("pinned box " + std::to_string(b) + " " + describe_box(box.first, box.second) +
                             " holds none of the object's inner particles" +
                             (o.kind == SolidKind::kCloth ? " (the cloth's vertices)"
                              : o.kind == SolidKind::kRod ? " (the rod's nodes)"
                                                          : "") +
                             "; move it onto the object");
    }
}

// Solids collide only with the domain walls: two objects, or an object and a static box, that
// start inside one another stay so, and their boundary particles count twice in the fluid's
// density. Refused when a moving object is involved; static solids may overlap one another (a
// static mesh sunk into a static floor box is a way to build scenery). An overlap shallower than
// the inner particles' depth (about r0/2) is not seen; touching is fine.
void check_objects_apart(const Scene& scene, const std::vector<PlacedObject>& placed,
                         const std::vector<Eigen::AlignedBox3d>& static_boxes) {
    const auto describe = [&](std::size_t k) {
        return "objects[" + std::to_string(k) + "] (" + scene.objects[k].name + ")";
    };
    for (std::size_t k = 0; k < placed.size(); ++k) {
        const PlacedObject& a = placed[k];
        for (std::size_t i = 0; a.moves && i < static_boxes.size(); ++i) {
            const Eigen::AlignedBox3d& box = static_boxes[i];
            const long inside = std::count_if(a.inner.begin(), a.inner.end(), [&](const Vec3d& x) { return box.contains(x); });
            if (inside > 0)
                throw InputError(scene.source + ": " + describe(k) + " overlaps static_boxes[" + std::to_string(i) +
                                 "]: " + std::to_string(inside) + " of its " + std::to_string(a.inner.size()) +
                                 " inner particles lie inside the box; objects do not collide with static boxes, so "
                                 "move it out (touching is fine)");
        }
    }
    // inside_count[k][j]: how many of object k's inner particles lie inside object j's mesh. Each
    // mesh is classified once, against the candidates of every object that may overlap it (the
    // ray tracer's scene is built per call).
    const std::size_t n = placed.size();
    std::vector<std::vector<long>> inside_count(n, std::vector<long>(n, 0));
    for (std::size_t j = 0; j < n; ++j) {
        const PlacedObject& b = placed[j];
        if (b.sheet) continue;  // a sheet has no inside
        std::vector<Vec3d> candidates;
        std::vector<std::size_t> owner;  // which object each candidate belongs to
        for (std::size_t k = 0; k < n; ++k) {
            const PlacedObject& a = placed[k];
            if (k == j || (!a.moves && !b.moves) || !a.bounds.intersects(b.bounds)) continue;
            for (const Vec3d& x : a.inner)
                if (b.bounds.contains(x)) {
                    candidates.push_back(x);
                    owner.push_back(k);
                }
        }
        if (candidates.empty()) continue;
        std::vector<std::uint8_t> inside;
        if (scene.params.dimensions == 2) {  // an outline
            const std::vector<std::array<int, 2>> edges = outline_edges(b.mesh);
            for (const Vec3d& x : candidates) inside.push_back(inside_outline(b.mesh, edges, x.x(), x.y()) ? 1 : 0);
        } else {
            inside = classify_points(b.mesh, candidates);
        }
        for (std::size_t c = 0; c < candidates.size(); ++c) inside_count[owner[c]][j] += inside[c];
    }
    // The first overlapping pair of objects in scene order is reported (after every object's
    // static-box check above).
    for (std::size_t k = 0; k < n; ++k)
        for (std::size_t j = 0; j < n; ++j)
            if (inside_count[k][j] > 0)
                throw InputError(scene.source + ": " + describe(k) + " overlaps " + describe(j) + ": " +
                                 std::to_string(inside_count[k][j]) + " of its " + std::to_string(placed[k].inner.size()) +
                                 " inner particles lie inside the other's mesh; objects do not collide with one "
                                 "another, so move them apart (touching is fine)");
}

}  // namespace

ParticleEstimate estimate_particles(const Scene& scene) {
    const double r0 = scene.params.fluid.spacing, rb = scene.boundary_spacing();
    ParticleEstimate n;
    const int dimensions = scene.params.dimensions;
    for (const auto& b : scene.fluid_blocks) n.fluid += lattice_count(b.min, b.max, r0, dimensions);
    if (scene.walls())
        n.boundary +=
            surface_count(scene.params.domain_min, scene.params.domain_max, rb, scene.boundary_layers, dimensions);
    for (const auto& b : scene.static_boxes) n.boundary += surface_count(b.min, b.max, rb, b.layers, dimensions);
    for (const auto& e : scene.emitters) {
        const double disc = dimensions == 2 ? 2 * std::floor(double(e.radius) / r0) + 1
                                            : std::max(1.0, M_PI * double(e.radius) * double(e.radius) / (r0 * r0));
        n.fluid += disc * std::ceil((e.end - e.start) * double(e.speed) / r0);
    }
    return n;
}

std::uint32_t emitter_layers(const SceneEmitter& e, double r0) {
    // Layer k leaves at start + k r0 / speed: those before `end` (one due within 1e-4 of an
    // interval before it counts as due at it: r0 and the speed are single precision).
    const double layers = std::ceil((e.end - e.start) * double(e.speed) / r0 - 1e-4);
    return static_cast<std::uint32_t>(std::max(1.0, std::min(layers, 4e9)));
}

long estimate_particle_count(const Scene& scene) {
    const double n = estimate_particles(scene).total();
    return n > 1e18 ? static_cast<long>(1e18) : static_cast<long>(n);
}

namespace {

// With heat conduction, every particle added since the last call starts at `t` (C).
void start_new_particles_at(const Scene& scene, SimulationSetup& setup, Real t) {
    if (scene.params.heat.enabled) setup.temperature.resize(setup.position.size(), t);
}

// The emitters' particles, pending until their layer leaves (algorithms/emitter.hpp), last so
// that nothing before them renumbers them.
void add_emitters(const Scene& scene, SimulationSetup& setup) {
    const Real r0 = scene.params.fluid.spacing;
    for (std::size_t k = 0; k < scene.emitters.size(); ++k) {
        const SceneEmitter& e = scene.emitters[k];
        EmitterSetup emitter;
        static_cast<EmitterParams&>(emitter) = e;
        emitter.name = e.name;
        emitter.offsets = disc_lattice(e.direction, e.radius, r0, scene.params.dimensions);
        emitter.layers = emitter_layers(e, r0);
        emitter.first = static_cast<std::uint32_t>(setup.position.size());
        const double count = double(emitter.layers) * double(emitter.offsets.size());
        if (double(setup.position.size()) + count > double(kMaxSceneParticles))
            throw InputError(scene.source + ": emitters[" + std::to_string(k) + "] (" + e.name + ") would release " +
                             std::to_string(static_cast<long>(count)) + " particles, more than the scene allows (" +
                             std::to_string(kMaxSceneParticles) + " in all); shorten it, slow it or narrow it");
        append(setup, std::vector<Vec3>(std::size_t(count), e.center), Vec3{0, 0, 0}, kPending, -1);
        start_new_particles_at(scene, setup, e.temperature);
        setup.emitters.push_back(std::move(emitter));
    }
}

}  // namespace

SimulationSetup build_setup(const Scene& scene, long* carved_fluid) {
    const long estimate = estimate_particle_count(scene);
    if (estimate > kMaxSceneParticles)
        throw InputError(scene.source + ": the scene would create about " + std::to_string(estimate) +
                         " particles (more than " + std::to_string(kMaxSceneParticles) +
                         "); increase fluid.spacing or shrink the domain");
    SimulationSetup setup;
    setup.params = scene.params;
    const Real r0 = scene.params.fluid.spacing;
    std::vector<std::size_t> block_end;  // fluid_blocks[i] fills [block_end[i - 1], block_end[i])
    const auto started_at = [&](Real t) { start_new_particles_at(scene, setup, t); };
    for (std::size_t i = 0; i < scene.fluid_blocks.size(); ++i) {
        const FluidBlock& b = scene.fluid_blocks[i];
        const std::vector<Vec3> points = fill_box_lattice(b.min, b.max, r0, scene.params.dimensions);
        if (points.empty())
            throw InputError(scene.source + ": fluid_blocks[" + std::to_string(i) +
                             "]: the block is thinner than fluid.spacing on some axis and holds no particle");
        append(setup, points, b.velocity, kFluid, -1);
        started_at(b.temperature);
        block_end.push_back(setup.position.size());
    }
    const Real rb = scene.boundary_spacing();
    setup.params.boundary.walls = scene.walls();
    setup.params.boundary.wall_gap = scene.walls() ? scene.wall_gap() : Real(-1);
    if (scene.walls())
        // The first layer where fluid blocks touching a wall start at rest density (wall_gap.hpp).
        append(setup,
               sample_container_walls(scene.params.domain_min, scene.params.domain_max, rb, scene.boundary_layers,
                                      scene.wall_gap(), scene.params.dimensions),
               Vec3{0, 0, 0}, kStaticBoundary, -1);
    started_at(scene.fluid_temperature);  // the walls are adiabatic: their temperature is never read
    const std::size_t first_solid = setup.position.size();
    std::vector<Eigen::AlignedBox3d> boxes;
    for (std::size_t i = 0; i < scene.static_boxes.size(); ++i) {
        const StaticBox& b = scene.static_boxes[i];
        // Where fluid rests against the box's layers, and the closest the carve below lets it
        // start: the walls' correction sets its band from them (algorithms/wall_contact.hpp).
        const Real gap = rest_density_wall_gap(r0, scene.params.fluid.support_radius, rb, b.layers,
                                               scene.params.fluid.kernel, scene.params.dimensions);
        const Real carved = carved_face_distance(Real(kFluidClearance) * r0, rb);
        setup.params.boundary.static_boxes.push_back(StaticBoxFaces{b.min, b.max, gap, carved});
        // One id space: objects[k] is body k, static_boxes[i] body (objects) + i.
        append(setup, sample_solid_box(b.min, b.max, rb, b.layers, scene.params.dimensions), Vec3{0, 0, 0},
               kStaticBoundary, static_cast<std::int32_t>(scene.objects.size() + i));
        boxes.emplace_back(Vec3d(b.min.x, b.min.y, b.min.z), Vec3d(b.max.x, b.max.y, b.max.z));
    }
    started_at(scene.fluid_temperature);  // static boxes are adiabatic too
    // Every object's mesh and inner particles, kept where there is something for it to overlap.
    // Static solids may overlap one another, so without a moving object there is nothing to check.
    const bool any_moving = std::any_of(scene.objects.begin(), scene.objects.end(),
                                        [](const SceneObject& o) { return o.kind != SolidKind::kStatic; });
    const bool check_overlaps =
        any_moving && (scene.objects.size() > 1 || (!scene.objects.empty() && !scene.static_boxes.empty()));
    std::vector<PlacedObject> placed;
    for (std::size_t k = 0; k < scene.objects.size(); ++k) {
        const SceneObject& o = scene.objects[k];
        SolidSetup solid;
        static_cast<SolidParams&>(solid) = o;
        solid.name = o.name;
        std::function<bool(const Vec3&)> pinned;
        if (o.pin == SceneObject::Pin::kBoxes) {
            const std::vector<std::pair<Vec3, Vec3>> boxes_pinned = o.pin_boxes;
            pinned = [boxes_pinned](const Vec3& x) {
                return std::any_of(boxes_pinned.begin(), boxes_pinned.end(), [&](const std::pair<Vec3, Vec3>& b) {
                    return inside_box(x, b.first, b.second);
                });
            };
        } else if (o.pin == SceneObject::Pin::kHalfSpace) {
            const Vec3 p = o.pin_point, n = o.pin_normal;
            pinned = [p, n](const Vec3& x) { return dot(x - p, n) < 0; };
        }
        const std::int32_t id = static_cast<std::int32_t>(k);
        try {
            PlacedObject object;
            object.mesh = object_mesh(scene, o);
            object.moves = o.kind != SolidKind::kStatic;
            const Aabb box = bounding_box(object.mesh);
            object.bounds = Eigen::AlignedBox3d(box.lo, box.hi);
            check_object_inside_domain(scene, box);
            check_object_particle_budget(scene, object.mesh, setup.position.size());
            const std::size_t first = setup.position.size();
            if (o.kind != SolidKind::kRod && object.mesh.triangles.empty())
                throw InputError(object.mesh.source + " has no triangles: a line is a rod's centreline (give the object "
                                 "kind \"rod\")");
            const double r0 = scene.params.fluid.spacing;
            const std::size_t inner =
                o.kind == SolidKind::kCloth ? add_cloth_object(setup, object.mesh, solid, o.velocity, id, r0, pinned)
                : o.kind == SolidKind::kRod ? add_rod_object(setup, object.mesh, solid, o.velocity, id, r0, pinned)
                                            : add_solid_object(setup, object.mesh, solid, o.velocity, id, r0,
                                                               scene.params.fluid.support_radius, pinned,
                                                               o.surface_spacing);
            object.sheet = is_thin(o.kind);
            check_pins_hold(o, setup, first, inner);
            started_at(o.temperature);
            // Fluid moving into a static object is stopped by its signed distance (where the
            // correction is on and there is fluid to stop), and so are moving solids
            // (solid_obstacles.hpp).
            const bool any_melts = std::any_of(scene.objects.begin(), scene.objects.end(),
                                               [](const SceneObject& other) { return other.melts(); });
            const bool stops_fluid = scene.params.boundary.correction && (scene.has_fluid() || any_melts);
            if (o.kind == SolidKind::kStatic && (stops_fluid || any_moving))
                add_static_object_distance(setup, object.mesh, scene.params.fluid.spacing, sealed_faces(scene));
            for (std::size_t i = first; check_overlaps && i < first + inner; ++i) {
                const Vec3 x = setup.position[i];
                object.inner.emplace_back(x.x, x.y, x.z);
            }
            if (check_overlaps) placed.push_back(std::move(object));
        } catch (const InputError& e) {
            throw InputError(scene.source + ": objects[" + std::to_string(k) + "] (" + o.name + "): " + e.what());
        }
        if (static_cast<long>(setup.position.size()) > kMaxSceneParticles)
            throw InputError(scene.source + ": the objects create more than " + std::to_string(kMaxSceneParticles) +
                             " particles; increase fluid.spacing");
    }
    check_objects_apart(scene, placed, boxes);
    // The static boxes are bodies after the objects: static, their particles numbered so, no mesh.
    for (std::size_t i = 0; i < scene.static_boxes.size(); ++i) {
        SolidSetup box;
        box.kind = SolidKind::kStatic;
        box.name = "static_box" + std::to_string(i);
        box.spacing = r0;
        setup.solids.push_back(std::move(box));
    }
    long carved = 0;
    if (setup.position.size() > first_solid) {
        const std::vector<std::uint8_t> removed = carve_fluid(setup, Real(kFluidClearance) * r0, boxes, first_solid);
        std::size_t begin = 0;
        for (std::size_t i = 0; i < block_end.size(); ++i) {
            const long block_carved = std::count(removed.begin() + long(begin), removed.begin() + long(block_end[i]), 1);
            if (block_carved == long(block_end[i] - begin))
                throw InputError(scene.source + ": fluid_blocks[" + std::to_string(i) +
                                 "]: static boxes and objects fill the whole block; no fluid particle is left");
            carved += block_carved;
            begin = block_end[i];
        }
    }
    if (carved_fluid) *carved_fluid = carved;
    add_emitters(scene, setup);
    setup.pressure_sensors = scene.pressure_sensors;
    return setup;
}

std::vector<std::uint8_t> carve_fluid(SimulationSetup& setup, Real clearance,
                                      const std::vector<Eigen::AlignedBox3d>& boxes, std::size_t first_solid) {
    const std::size_t n = setup.position.size();
    std::vector<Vec3> fluid, solid_points;
    std::vector<std::size_t> fluid_index;
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint8_t t = setup.type[i];
        if (t == kFluid) {
            fluid.push_back(setup.position[i]);
            fluid_index.push_back(i);
        } else if (i >= first_solid && (t == kStaticBoundary || t == kSurfaceBoundary || t == kInnerBoundary)) {
            solid_points.push_back(setup.position[i]);
        }
    }
    const std::vector<std::uint8_t> occupied = points_solids_occupy(fluid, solid_points, boxes, clearance);
    std::vector<std::uint8_t> removed(n, 0);
    for (std::size_t f = 0; f < fluid.size(); ++f) removed[fluid_index[f]] = occupied[f];
    // Compact the lists and renumber the solids' references to them.
    std::vector<std::uint32_t> new_index(n);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n; ++i) {
        new_index[i] = static_cast<std::uint32_t>(kept);
        if (removed[i]) continue;
        setup.position[kept] = setup.position[i];
        setup.velocity[kept] = setup.velocity[i];
        setup.type[kept] = setup.type[i];
        setup.object[kept] = setup.object[i];
        if (!setup.temperature.empty()) setup.temperature[kept] = setup.temperature[i];
        ++kept;
    }
    setup.position.resize(kept);
    setup.velocity.resize(kept);
    setup.type.resize(kept);
    setup.object.resize(kept);
    if (!setup.temperature.empty()) setup.temperature.resize(kept);
    for (SolidSetup& solid : setup.solids)
        for (std::vector<std::uint32_t>* list : {&solid.ibp, &solid.gp, &solid.sbp})
            for (std::uint32_t& index : *list) index = new_index[index];
    return removed;
}

TriangleMesh object_mesh(const Scene& scene, const SceneObject& o) {
    TriangleMesh mesh;
    const bool plane = scene.params.dimensions == 2;
    if (!o.mesh_procedural.empty()) {
        // A 2D object is an outline (sampling/outline.hpp); a rod's centreline is a line in either.
        const bool line = parse_procedural_spec(o.mesh_procedural).kind == "line";
        mesh = plane && !line ? make_outline_from_spec(o.mesh_procedural) : make_procedural_from_spec(o.mesh_procedural);
    } else {
        std::filesystem::path path(o.mesh_file);
        if (path.is_relative() && !scene.base_dir.empty()) path = std::filesystem::path(scene.base_dir) / path;
        std::error_code error;
        if (!std::filesystem::exists(path, error))
            throw InputError(path.string() + ": mesh file does not exist (mesh.file \"" + o.mesh_file_given +
                             "\" is read relative to " +
                             (scene.base_dir.empty() ? std::string("the working directory")
                                                     : "the scene file's folder " + scene.base_dir) +
                             "; the meshes shipped with Meltwater are in shared/assets/meshes, beside the checkout: "
                             "../shared/assets/meshes from its root)");
        mesh = plane ? load_outline(path.string()) : load_obj(path.string());
    }
    MeshTransform t;
    t.scale = Vec3d(o.scale.x, o.scale.y, o.scale.z);
    t.rotation_deg = Vec3d(o.rotation_deg.x, o.rotation_deg.y, o.rotation_deg.z);
    t.translation = Vec3d(o.translation.x, o.translation.y, o.translation.z);
    apply_transform(mesh, t);
    return mesh;
}

std::size_t add_solid_object(SimulationSetup& setup, const TriangleMesh& mesh, SolidSetup solid, Vec3 velocity,
                             std::int32_t object_id, double r0, double h,
                             const std::function<bool(const Vec3&)>& pinned, double surface_spacing) {
    SampleOptions options;
    options.measure_coverage = false;
    options.surface.candidate_gap *= surface_spacing;
    options.surface.min_distance *= surface_spacing;
    options.surface.coverage *= surface_spacing;
    OutlineSampleOptions outline_options;
    outline_options.surface_spacing = surface_spacing;
    // Only an elastic or rigid object's SBPs follow GPs: no refinement for the others.
    if (solid.kind == SolidKind::kStatic || solid.melts()) options.geometry_max_edge = 0;
    const bool outline = setup.params.dimensions == 2;  // the object is an outline (sampling/outline.hpp)
    const SolidSample sample = outline ? sample_outline(mesh, r0, h, outline_options) : sample_solid(mesh, r0, h, options);
    if (sample.ibp.count() == 0)
        throw InputError("the mesh holds no inner particle at spacing " + std::to_string(r0) +
                         " (make it larger or decrease fluid.spacing)");
    auto to_vec3 = [](const Vec3d& v) { return Vec3{Real(v.x()), Real(v.y()), Real(v.z())}; };
    auto push = [&](const Vec3& x, std::uint8_t type) {
        setup.position.push_back(x);
        setup.velocity.push_back(solid.kind == SolidKind::kStatic ? Vec3{0, 0, 0} : velocity);
        setup.type.push_back(type);
        setup.object.push_back(object_id);
        return static_cast<std::uint32_t>(setup.position.size() - 1);
    };
    solid.spacing = Real(r0);
    // The sampler's mesh: oriented outward and, for a moving object, refined (its GPs' mesh).
    solid.triangles = sample.geometry.triangles;
    if (solid.kind == SolidKind::kStatic) {
        for (const auto& p : sample.ibp.positions) push(to_vec3(p), kStaticBoundary);
        for (const auto& p : sample.sbp.positions) push(to_vec3(p), kStaticBoundary);
        for (const auto& v : mesh.vertices) solid.rest_vertices.push_back(to_vec3(v));
        setup.solids.push_back(std::move(solid));
        return sample.ibp.count();
    }
    if (solid.melts()) {
        // A melting object is its lattice alone (algorithms/melting.hpp): a vertex missing one of
        // its 26 one-ring neighbours is an SBP, any other an IBP. Its mesh cannot follow it as it
        // melts, so no GPs, no mesh SBPs, and no mesh in the frames.
        const std::vector<std::array<int, 3>> lattice(sample.ibp.lattice.begin(), sample.ibp.lattice.end());
        const std::vector<std::uint8_t> ring = lattice_one_ring_counts(lattice);
        for (std::size_t k = 0; k < sample.ibp.count(); ++k) {
            const Vec3 x = to_vec3(sample.ibp.positions[k]);
            solid.ibp.push_back(push(x, ring[k] < full_one_ring(setup.params.dimensions) ? kSurfaceBoundary : kInnerBoundary));
            solid.lattice.push_back(lattice[k]);
            solid.pinned.push_back(pinned && pinned(x) ? 1 : 0);
            if (outline) solid.ibp_mass.push_back(Real(double(solid.density) * r0 * r0));
        }
        solid.triangles.clear();
        solid.gp_offsets.assign(1, 0);
        setup.solids.push_back(std::move(solid));
        return sample.ibp.count();
    }
    for (std::size_t k = 0; k < sample.ibp.count(); ++k) {
        const Vec3 x = to_vec3(sample.ibp.positions[k]);
        solid.ibp.push_back(push(x, kInnerBoundary));
        solid.lattice.push_back(sample.ibp.lattice[k]);
        solid.pinned.push_back(pinned && pinned(x) ? 1 : 0);
        // A 2D IBP is an r0 × r0 square of the solid (mass per unit depth, as the fluid's).
        if (outline) solid.ibp_mass.push_back(Real(double(solid.density) * r0 * r0));
    }
    for (std::size_t g = 0; g < sample.gp.count(); ++g) solid.gp.push_back(push(to_vec3(sample.gp.positions[g]), kGeometry));
    solid.gp_offsets = sample.gp.offsets;
    solid.gp_links = sample.gp.ibp;
    for (double w : sample.gp.weight) solid.gp_weights.push_back(Real(w));
    // A rigid or elastic object's SBPs set in (coupling.surface_inset): as far inside the face as
    // a wall's single layer of spacing r0/2 sits outside it, half the thickness where the object
    // is thinner; an open mesh has no inside to set them into. An elastic object thinner than
    // twice the support radius anywhere (a thin-walled box, a plate, a hollow ring) keeps them on
    // its faces: set in, the light thin box of scenes/thin_box_pour.json (walls 2 r0) was thrown
    // to 17 m/s where the stream struck it (4.5 m/s on its faces; docs/coupling.md).
    std::vector<double> inset(sample.sbp.count(), 0.0);
    const bool solid_kind = solid.kind == SolidKind::kRigid || solid.kind == SolidKind::kElastic;
    if (setup.params.coupling.surface_inset && solid_kind && sample.stats.closed) {
        // A 2D object's SBPs are one line at their own spacing; a 3D object's, about 2.5 an r0²,
        // stand as a wall's layer at r0/2 does.
        const double layer_spacing = outline ? surface_spacing * r0 : r0 / 2;
        const double depth = rest_density_wall_gap(Real(r0), Real(h), Real(layer_spacing), 1, setup.params.fluid.kernel,
                                                   setup.params.dimensions);
        // One ray per SBP: its half thickness up to `probe` (h for an elastic object, to find the
        // thin ones; depth, never more than h, sets the inset).
        const double probe = solid.kind == SolidKind::kElastic ? std::max(h, depth) : depth;
        const std::vector<double> half_thickness = outline ? outline_insets(sample.geometry, sample.sbp, probe)
                                                           : surface_insets(sample.geometry, sample.sbp, probe);
        const bool thin_elastic = solid.kind == SolidKind::kElastic &&
                                  std::any_of(half_thickness.begin(), half_thickness.end(), [&](double d) { return d < h; });
        if (!thin_elastic)
            for (std::size_t k = 0; k < inset.size(); ++k) inset[k] = std::min(depth, half_thickness[k]);
    }
    // Where each step puts them (solid_face.hpp: faded near the domain walls and the static boxes).
    const BoundaryParams& walls = setup.params.boundary;
    const Real fade = surface_inset_fade(walls.walls, setup.params.fluid.support_radius, walls.wall_gap, walls.static_boxes);
    Vec3 fade_lo, fade_hi;
    faces_to_fade_at(walls.walls, setup.params.domain_min, setup.params.domain_max, fade_lo, fade_hi);
    for (std::size_t k = 0; k < sample.sbp.count(); ++k) {
        const Real faded = faded_inset(Real(inset[k]), to_vec3(sample.sbp.positions[k]), to_vec3(sample.sbp.normals[k]),
                                       fade_lo, fade_hi, fade, walls.static_boxes);
        const Vec3d set_in = sample.sbp.positions[k] - double(faded) * sample.sbp.normals[k];
        solid.sbp.push_back(push(to_vec3(set_in), kSurfaceBoundary));
        solid.sbp_inset.push_back(Real(inset[k]));
        // Barycentric weights refer to the corners of the sampler's (oriented) triangle.
        solid.sbp_corners.push_back(solid.triangles[std::size_t(sample.sbp.triangles[k])]);
        solid.sbp_barycentric.push_back(to_vec3(sample.sbp.barycentric[k]));
        solid.sbp_normal.push_back(to_vec3(sample.sbp.normals[k]));
    }
    setup.solids.push_back(std::move(solid));
    return sample.ibp.count();
}

namespace {

// A thin object's particles (cloth, rod), appended to the setup with `velocity`: its nodes
// (`nodes`, each weighing `mass[v]`, pinned where `pinned` says, linked along the graph for the
// regions) as IBPs, each node again as its own GP (its mesh or line follows the nodes exactly),
// then SBPs pushed by the returned function.
class ThinObjectParticles {
   public:
    ThinObjectParticles(SimulationSetup& setup, SolidSetup& solid, Vec3 velocity, std::int32_t object_id)
        : setup_(setup), solid_(solid), velocity_(velocity), object_id_(object_id) {}

    static Vec3 to_vec3(const Vec3d& v) { return Vec3{Real(v.x()), Real(v.y()), Real(v.z())}; }

    void add_nodes(const std::vector<Vec3d>& nodes, const std::vector<double>& mass,
                   const std::vector<std::uint32_t>& graph_offsets, const std::vector<std::uint32_t>& graph_links,
                   const std::function<bool(const Vec3&)>& pinned) {
        for (std::size_t v = 0; v < nodes.size(); ++v) {
            const Vec3 x = to_vec3(nodes[v]);
            solid_.ibp.push_back(push(x, kInnerBoundary));
            solid_.pinned.push_back(pinned && pinned(x) ? 1 : 0);
            solid_.ibp_mass.push_back(Real(mass[v]));
        }
        solid_.ibp_graph_offsets = graph_offsets;
        solid_.ibp_graph_links = graph_links;
        solid_.gp_offsets.assign(1, 0);
        for (std::size_t v = 0; v < nodes.size(); ++v) {
            solid_.gp.push_back(push(to_vec3(nodes[v]), kGeometry));
            solid_.gp_links.push_back(int(v));
            solid_.gp_weights.push_back(Real(1));
            solid_.gp_offsets.push_back(int(v + 1));
        }
    }
    // An SBP at x on the "triangle" `corners` (GP indices) with barycentric weights and normal.
    void add_sbp(const Vec3d& x, const std::array<int, 3>& corners, const Vec3d& barycentric, const Vec3d& normal) {
        solid_.sbp.push_back(push(to_vec3(x), kSurfaceBoundary));
        solid_.sbp_corners.push_back(corners);
        solid_.sbp_barycentric.push_back(to_vec3(barycentric));
        solid_.sbp_normal.push_back(to_vec3(normal));
    }

   private:
    std::uint32_t push(const Vec3& x, std::uint8_t type) {
        setup_.position.push_back(x);
        setup_.velocity.push_back(velocity_);
        setup_.type.push_back(type);
        setup_.object.push_back(object_id_);
        return static_cast<std::uint32_t>(setup_.position.size() - 1);
    }

    SimulationSetup& setup_;
    SolidSetup& solid_;
    Vec3 velocity_;
    std::int32_t object_id_;
};

}  // namespace

std::size_t add_cloth_object(SimulationSetup& setup, const TriangleMesh& mesh, SolidSetup solid, Vec3 velocity,
                             std::int32_t object_id, double r0, const std::function<bool(const Vec3&)>& pinned) {
    const SheetSample sheet = sample_sheet(mesh, r0);
    solid.spacing = Real(r0);
    solid.triangles = sheet.mesh.triangles;
    // One layer of thickness r0: a node weighs its area times density r0 (a flat grid at spacing
    // r0 has nodes of density r0^3, like a lattice's).
    std::vector<double> mass(sheet.node_area.size());
    for (std::size_t v = 0; v < mass.size(); ++v) mass[v] = double(solid.density) * r0 * sheet.node_area[v];
    ThinObjectParticles particles(setup, solid, velocity, object_id);
    particles.add_nodes(sheet.mesh.vertices, mass, sheet.graph_offsets, sheet.graph_links, pinned);
    for (std::size_t k = 0; k < sheet.sbp.count(); ++k)
        particles.add_sbp(sheet.sbp.positions[k], solid.triangles[std::size_t(sheet.sbp.triangles[k])],
                          sheet.sbp.barycentric[k], sheet.sbp.normals[k]);
    setup.solids.push_back(std::move(solid));
    return mass.size();
}

std::size_t add_rod_object(SimulationSetup& setup, const TriangleMesh& line, SolidSetup solid, Vec3 velocity,
                           std::int32_t object_id, double r0, const std::function<bool(const Vec3&)>& pinned) {
    const RodSample rod = sample_rod(line, r0);
    solid.spacing = Real(r0);
    // One line of section r0 × r0 (in 2D of width r0): a node r0 from its neighbours weighs
    // density r0³ (r0²), as a lattice's IBP does.
    const double section = setup.params.dimensions == 2 ? r0 : r0 * r0;
    std::vector<double> mass(rod.nodes.size());
    for (std::size_t v = 0; v < mass.size(); ++v) mass[v] = double(solid.density) * section * rod.node_length[v];
    ThinObjectParticles particles(setup, solid, velocity, object_id);
    particles.add_nodes(rod.nodes, mass, rod.graph_offsets, rod.graph_links, pinned);
    // An SBP on segment (a, b) is a "triangle" (a, b, b) (SbpLink::is_segment); its stored
    // normal is the segment's tangent (kSbpAround).
    for (std::size_t k = 0; k < rod.sbp.size(); ++k) {
        const int a = int(rod.sbp_segment[k]), b = a + 1;
        const double f = rod.sbp_fraction[k];
        particles.add_sbp(rod.sbp[k], {a, b, b}, Vec3d(1 - f, f, 0),
                          (rod.nodes[std::size_t(b)] - rod.nodes[std::size_t(a)]).normalized());
    }
    setup.solids.push_back(std::move(solid));
    return mass.size();
}

bool add_static_object_distance(SimulationSetup& setup, const TriangleMesh& mesh, double r0, const SealedFace& sealed) {
    const double contact = kStaticObjectContact * r0;
    const SignedDistanceGrid sdf = setup.params.dimensions == 2
                                       ? signed_distance_outline(mesh, r0 / 2, contact, kMaxObjectDistanceNodes, sealed)
                                       : signed_distance_grid(mesh, r0 / 2, contact, kMaxObjectDistanceNodes, sealed);
    if (sdf.exit_triangles == 0) return false;
    std::vector<Real>& values = setup.params.boundary.static_object_distances;
    if (values.size() + sdf.distance.size() > std::size_t(UINT32_MAX))
        throw InputError("the static objects' distance grids hold more than 2^32 values; increase fluid.spacing");
    ContactField c;
    c.contact = Real(contact);
    c.field.origin = Vec3{Real(sdf.grid.origin.x()), Real(sdf.grid.origin.y()), Real(sdf.grid.origin.z())};
    c.field.inv_spacing = Real(1 / sdf.grid.spacing);
    c.field.nx = sdf.grid.dims[0];
    c.field.ny = sdf.grid.dims[1];
    c.field.nz = sdf.grid.dims[2];
    c.field.first = static_cast<std::uint32_t>(values.size());
    for (double d : sdf.distance) values.push_back(Real(d));
    setup.params.boundary.static_objects.push_back(c);
    return true;
}

SealedFace sealed_faces(const Scene& scene) {
    // A thousandth of r0: a face meant to stand on the floor or a box lies there to rounding.
    const double tolerance = 1e-3 * double(scene.params.fluid.spacing);
    const bool walls = scene.walls();
    const int axes = scene.params.dimensions;  // a 2D domain is flat in z, and has no walls there
    const Vec3d lo(scene.params.domain_min.x, scene.params.domain_min.y, scene.params.domain_min.z);
    const Vec3d hi(scene.params.domain_max.x, scene.params.domain_max.y, scene.params.domain_max.z);
    std::vector<Eigen::AlignedBox3d> boxes;
    for (const StaticBox& b : scene.static_boxes)
        boxes.emplace_back(Vec3d(b.min.x, b.min.y, b.min.z) - Vec3d::Constant(tolerance),
                           Vec3d(b.max.x, b.max.y, b.max.z) + Vec3d::Constant(tolerance));
    return [=](const Vec3d& a, const Vec3d& b, const Vec3d& c) {
        for (int axis = 0; walls && axis < axes; ++axis) {
            if (std::max({a[axis], b[axis], c[axis]}) <= lo[axis] + tolerance) return true;
            if (std::min({a[axis], b[axis], c[axis]}) >= hi[axis] - tolerance) return true;
        }
        for (const Eigen::AlignedBox3d& box : boxes)
            if (box.contains(a) && box.contains(b) && box.contains(c)) return true;
        return false;
    };
}

ParticleCounts count_particles(const SimulationSetup& setup) {
    ParticleCounts c;
    for (std::uint8_t t : setup.type)
        if (t < kParticleTypeCount) ++c.by_type[t];
    return c;
}

std::string emitter_overlap_warning(const SimulationSetup& setup) {
    // Closer than the rest spacing r0, less a margin for rounding: the layer would be denser than rest.
    const double reach = 0.9 * double(setup.params.fluid.spacing);
    const auto to_vec3d = [](Vec3 x) { return Vec3d(x.x, x.y, x.z); };
    for (std::size_t k = 0; k < setup.emitters.size(); ++k) {
        const EmitterSetup& e = setup.emitters[k];
        // The disc's points, and their box grown by the reach: most particles fail the box test.
        std::vector<Vec3d> disc;
        Eigen::AlignedBox3d box;
        for (const Vec3& offset : e.offsets) box.extend(disc.emplace_back(to_vec3d(e.center + offset)));
        box.min().array() -= reach;
        box.max().array() += reach;
        const PointTree tree(disc);
        long overlapping = 0;
        double nearest = reach;
        std::uint8_t nearest_type = kFluid;
        for (std::size_t i = 0; i < setup.position.size(); ++i) {
            const Vec3d x = to_vec3d(setup.position[i]);
            if (setup.type[i] == kPending || !box.contains(x)) continue;
            const double closest = tree.nearest(x).second;
            if (closest >= reach) continue;
            ++overlapping;
            if (closest < nearest) {
                nearest = closest;
                nearest_type = setup.type[i];
            }
        }
        if (overlapping == 0) continue;
        char text[400];
        const char* what = nearest_type == kFluid             ? "fluid particle"
                           : nearest_type == kStaticBoundary ? "particle of a wall, a static box or a static object"
                                                             : "particle of a moving object";
        std::snprintf(text, sizeof text,
                      "emitters[%zu] (%s): its disc starts closer than 0.9 r0 to %ld particle(s) of the scene (the "
                      "nearest a %s, %.3g m from it), so its layers would be released on top of them; move the "
                      "disc clear of the fluid and the solids (docs/scenes.md, \"Emitters\")",
                      k, e.name.c_str(), overlapping, what, nearest);
        return text;
    }
    return "";
}

}  // namespace mw
