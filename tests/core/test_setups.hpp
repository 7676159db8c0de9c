// Small programmatic scenes for the physics tests (the JSON route is tested in tests/cli).
#pragma once
#include "algorithms/simulation.hpp"
#include "sampling/box_particles.hpp"

namespace mw::test {

// A box of fluid [block_lo, block_hi] in a domain [lo, hi] lined with Akinci walls at spacing r0/2,
// the first layer kWallGap r0 outside the faces (the fluid starts at rest density).
inline SimulationSetup fluid_in_box(Vec3 lo, Vec3 hi, Vec3 block_lo, Vec3 block_hi, Real r0, Real dt) {
    SimulationSetup setup;
    setup.params.domain_min = lo;
    setup.params.domain_max = hi;
    setup.params.fluid.spacing = r0;
    setup.params.fluid.support_radius = 2 * r0;
    setup.params.fluid.rest_density = 1000;
    setup.params.solver.dt = dt;
    for (const Vec3& p : fill_box_lattice(block_lo, block_hi, r0)) {
        setup.position.push_back(p);
        setup.type.push_back(kFluid);
    }
    for (const Vec3& p : sample_container_walls(lo, hi, r0 / 2, 1, kWallGap * r0)) {
        setup.position.push_back(p);
        setup.type.push_back(kStaticBoundary);
    }
    setup.velocity.assign(setup.position.size(), Vec3{0, 0, 0});
    setup.object.assign(setup.position.size(), -1);
    return setup;
}

}  // namespace mw::test
