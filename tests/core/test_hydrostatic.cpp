// A column of water at rest: after settling, interior pressures follow ρ0 g (H - y) within 2% of
// ρ0 g H, and the mean density error stays below η.
#include <doctest/doctest.h>

#include <cstdio>

#include "backend/backend_registry.hpp"
#include "test_setups.hpp"

using namespace mw;

TEST_CASE("hydrostatic column settles to the analytic pressure") {
    const Real r0 = 0.02f, H = 0.5f, width = 0.2f;
    SimulationSetup setup =
        test::fluid_in_box({0, 0, 0}, {width, 0.7f, width}, {0, 0, 0}, {width, H, width}, r0, 0.002f);
    setup.params.fluid.viscosity = 0.05f;  // damps the settling sloshing
    auto sim = create_openmp_simulation(setup, 0);
    double max_avg_error = 0;
    for (int step = 0; step < 600; ++step) {
        sim->step();
        if (step >= 500) max_avg_error = std::max(max_avg_error, sim->last_report().density_error_avg);
    }
    CHECK(max_avg_error < setup.params.solver.eta);

    HostParticles particles;
    sim->download(particles);
    const double rho_g = 1000.0 * 9.81, margin = 2 * 2 * r0;  // two support radii from walls and surface
    double worst = 0;
    int interior = 0;
    for (std::size_t i = 0; i < particles.position.size(); ++i) {
        if (particles.type[i] != kFluid) continue;
        const Vec3 x = particles.position[i];
        if (x.x < margin || x.x > width - margin || x.z < margin || x.z > width - margin || x.y < margin ||
            x.y > H - margin)
            continue;
        ++interior;
        worst = std::max(worst, std::fabs(particles.pressure[i] - rho_g * (H - x.y)) / (rho_g * H));
    }
    MESSAGE("interior particles " << interior << ", worst pressure deviation " << worst * 100
                                  << "% of rho0 g H, mean density error " << max_avg_error * 100 << "%");
    REQUIRE(interior > 50);
    CHECK(worst < 0.02);
}
