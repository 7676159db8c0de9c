#include "apps/scene_builder.hpp"

#include <cmath>
#include <string>

#include "backend/errors.hpp"
#include "sampling/box_particles.hpp"

namespace mw {

namespace {
double lattice_count(Vec3 lo, Vec3 hi, double spacing) {
    return std::floor((hi.x - lo.x) / spacing + 1e-4) * std::floor((hi.y - lo.y) / spacing + 1e-4) *
           std::floor((hi.z - lo.z) / spacing + 1e-4);
}
double surface_count(Vec3 lo, Vec3 hi, double spacing, int layers) {
    const double a = hi.x - lo.x + 2 * layers * spacing, b = hi.y - lo.y + 2 * layers * spacing,
                 c = hi.z - lo.z + 2 * layers * spacing;
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
}  // namespace

long estimate_particle_count(const Scene& scene) {
    const double r0 = scene.params.fluid.spacing, rb = scene.boundary_spacing();
    double n = 0;
    for (const auto& b : scene.fluid_blocks) n += lattice_count(b.min, b.max, r0);
    if (scene.walls) n += surface_count(scene.params.domain_min, scene.params.domain_max, rb, scene.boundary_layers);
    for (const auto& b : scene.static_boxes) n += surface_count(b.min, b.max, rb, b.layers);
    return n > 1e18 ? static_cast<long>(1e18) : static_cast<long>(n);
}

SimulationSetup build_setup(const Scene& scene) {
    const long estimate = estimate_particle_count(scene);
    if (estimate > kMaxSceneParticles)
        throw InputError(scene.source + ": the scene would create about " + std::to_string(estimate) +
                         " particles (more than " + std::to_string(kMaxSceneParticles) +
                         "); increase fluid.spacing or shrink the domain");
    SimulationSetup setup;
    setup.params = scene.params;
    const Real r0 = scene.params.fluid.spacing;
    for (std::size_t i = 0; i < scene.fluid_blocks.size(); ++i) {
        const FluidBlock& b = scene.fluid_blocks[i];
        const std::vector<Vec3> points = fill_box_lattice(b.min, b.max, r0);
        if (points.empty())
            throw InputError(scene.source + ": fluid_blocks[" + std::to_string(i) +
                             "]: the block is thinner than fluid.spacing on some axis and holds no particle");
        append(setup, points, b.velocity, kFluid, -1);
    }
    const Real rb = scene.boundary_spacing();
    if (scene.walls)
        append(setup, sample_container_walls(scene.params.domain_min, scene.params.domain_max, rb, scene.boundary_layers),
               Vec3{0, 0, 0}, kStaticBoundary, -1);
    for (std::size_t i = 0; i < scene.static_boxes.size(); ++i) {
        const StaticBox& b = scene.static_boxes[i];
        append(setup, sample_solid_box(b.min, b.max, rb, b.layers), Vec3{0, 0, 0}, kStaticBoundary,
               static_cast<std::int32_t>(i));
    }
    return setup;
}

ParticleCounts count_particles(const SimulationSetup& setup) {
    ParticleCounts c;
    for (std::uint8_t t : setup.type)
        if (t < kParticleTypeCount) ++c.by_type[t];
    return c;
}

}  // namespace mw
