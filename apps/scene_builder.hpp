// Scene -> the initial particles of a simulation: fluid blocks on a lattice, the domain walls and
// static boxes as Akinci boundary particles.
#pragma once
#include "algorithms/simulation.hpp"
#include "apps/scene.hpp"

namespace mw {

// Refuses (InputError) scenes that would create more than this many particles.
constexpr long kMaxSceneParticles = 200'000'000;

// A quick count of the particles build_setup() would create, without creating them.
long estimate_particle_count(const Scene& scene);

SimulationSetup build_setup(const Scene& scene);

// Particle counts of a setup by type.
ParticleCounts count_particles(const SimulationSetup& setup);

}  // namespace mw
