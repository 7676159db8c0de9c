// Scene -> the initial particles of a simulation: fluid blocks on a lattice, the domain walls and
// static boxes as Akinci boundary particles.
#pragma once
#include <functional>

#include <Eigen/Geometry>

#include "simulation/simulation.hpp"
#include "apps/scene.hpp"
#include "sampling/fluid_clearance.hpp"
#include "sampling/mesh.hpp"
#include "sampling/signed_distance.hpp"

namespace mw {

// Refuses (InputError) scenes that would create more than this many particles.
constexpr long kMaxSceneParticles = 200'000'000;

// A quick count of the particles build_setup() would create, without creating them (objects,
// known only once sampled, are left out).
struct ParticleEstimate {
    double fluid = 0, boundary = 0;
    double total() const { return fluid + boundary; }
};
ParticleEstimate estimate_particles(const Scene& scene);
// Layers an emitter releases (each r0 / speed after the last, from start until end).
std::uint32_t emitter_layers(const SceneEmitter& e, double r0);
long estimate_particle_count(const Scene& scene);

// The particles of the scene. Fluid is carved out where static boxes and objects stand (see
// carve_fluid); `carved_fluid`, when given, receives how many fluid particles that removed.
SimulationSetup build_setup(const Scene& scene, long* carved_fluid = nullptr);

// Removes the fluid particles that solids occupy (points_solids_occupy, with clearance
// kFluidClearance r0 in scenes): those inside one of `boxes` and those closer than `clearance` to
// a static, surface or inner boundary particle at index >= first_solid (the domain walls, placed
// before first_solid, sit 0.31–1.23 r0 outside the domain, wall_gap.hpp, and never come that
// close). Indices in setup.solids are renumbered. Returns, for every particle before the call,
// whether it was removed.
std::vector<std::uint8_t> carve_fluid(SimulationSetup& setup, Real clearance,
                                      const std::vector<Eigen::AlignedBox3d>& boxes, std::size_t first_solid);

// Samples `mesh` (already in world coordinates) at spacing r0 and support h and appends the object
// to `setup`: its IBPs, SBPs and GPs as particles (static objects: IBPs and SBPs as static boundary
// particles) with `velocity`, and a SolidSetup built from `solid` (kind, density, LSM settings,
// name) with the particle links filled in. IBPs for which `pinned` is true stay at rest. Returns
// the number of inner particles, which are appended first. An outline (sampling/outline.hpp)
// is a 2D object. Its SBPs lie at most `surface_spacing` r0 apart (in 3D the surface sampler's
// distances scale by it).
std::size_t add_solid_object(SimulationSetup& setup, const TriangleMesh& mesh, SolidSetup solid, Vec3 velocity,
                      std::int32_t object_id, double r0, double h,
                      const std::function<bool(const Vec3&)>& pinned = nullptr, double surface_spacing = 1);

// A cloth (docs/cloth.md): `mesh` (world coordinates), an open sheet, refined to edges of at most 1.5
// r0 (sampling/sheet_sample.hpp). Each vertex is a shape-matching node (an IBP, with its share of
// the sheet's area times density r0 as its mass) and a GP; the SBPs are sampled on the triangles.
// Nodes for which `pinned` is true stay at rest. Returns the number of nodes, appended first.
std::size_t add_cloth_object(SimulationSetup& setup, const TriangleMesh& mesh, SolidSetup solid, Vec3 velocity,
                             std::int32_t object_id, double r0, const std::function<bool(const Vec3&)>& pinned = nullptr);

// A rod (docs/rods.md): `line` (world coordinates), its centreline, resampled at steps of at most r0
// (sampling/rod_sample.hpp). Each node is a shape-matching node (an IBP, with its share of the
// length times density r0² as its mass) and a GP; the SBPs lie on the segments between nodes.
// Nodes for which `pinned` is true stay at rest. Returns the number of nodes, appended first.
std::size_t add_rod_object(SimulationSetup& setup, const TriangleMesh& line, SolidSetup solid, Vec3 velocity,
                           std::int32_t object_id, double r0, const std::function<bool(const Vec3&)>& pinned = nullptr);

// The correction's signed distance grid of a static mesh object (algorithms/wall_contact.hpp),
// appended to setup.params (static_objects, static_object_distances): at spacing r0/2, reaching
// the band and two nodes past it outside the mesh's bounding box, at most
// kMaxObjectDistanceNodes nodes (coarser beyond that). `sealed` marks the triangles that are no
// way out (sampling/signed_distance.hpp); an object whose triangles are all sealed gets no grid.
// Returns whether a grid was added.
constexpr std::size_t kMaxObjectDistanceNodes = 8'000'000;
bool add_static_object_distance(SimulationSetup& setup, const TriangleMesh& mesh, double r0,
                                const SealedFace& sealed = nullptr);

// The triangles of a scene's static objects that fluid cannot reach from outside, and so that
// are no way out of them: those lying on (or beyond) a face of the domain when it has walls, and
// those inside (or on) a static box.
SealedFace sealed_faces(const Scene& scene);

// The mesh of a scene object in world coordinates (file or procedural, then the transform).
TriangleMesh object_mesh(const Scene& scene, const SceneObject& object);

// Particle counts of a setup by type.
ParticleCounts count_particles(const SimulationSetup& setup);

// A warning ("" if none) for the first emitter whose disc starts closer than 0.9 r0 to a
// particle of the scene (fluid, a wall, a box, an object): its layers would be released on top of
// that particle. Nothing else keeps a disc clear (algorithms/emitter.hpp).
std::string emitter_overlap_warning(const SimulationSetup& setup);

}  // namespace mw
