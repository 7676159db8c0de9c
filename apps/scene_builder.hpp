// Scene -> the initial particles of a simulation: fluid blocks on a lattice, the domain walls and
// static boxes as Akinci boundary particles.
#pragma once
#include <functional>

#include "algorithms/simulation.hpp"
#include "apps/scene.hpp"
#include "sampling/mesh.hpp"

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
long estimate_particle_count(const Scene& scene);

SimulationSetup build_setup(const Scene& scene);

// Samples `mesh` (already in world coordinates) at spacing r0 and support h and appends the object
// to `setup`: its IBPs, SBPs and GPs as particles (static objects: IBPs and SBPs as static boundary
// particles) with `velocity`, and a SolidSetup built from `solid` (kind, density, LSM settings,
// name) with the particle links filled in. IBPs for which `pinned` is true stay at rest.
void add_solid_object(SimulationSetup& setup, const TriangleMesh& mesh, SolidSetup solid, Vec3 velocity,
                      std::int32_t object_id, double r0, double h,
                      const std::function<bool(const Vec3&)>& pinned = nullptr);

// The mesh of a scene object in world coordinates (file or procedural, then the transform).
TriangleMesh object_mesh(const Scene& scene, const SceneObject& object);

// Particle counts of a setup by type.
ParticleCounts count_particles(const SimulationSetup& setup);

}  // namespace mw
