// Dam break against Martin & Moyce (1952): column a wide and 2a high, front Z = x/a against
// T = t sqrt(2g/a) (table in METHOD.md).
//
// Measured with free-slip walls and no tuning (r0 = a/20; the same numbers at a/10 and a/40):
// the front matches at T = 0.41, then leads the experiment by up to about 21% around T = 1.2 and
// by about 11% at T = 2.5, advancing at the experiment's speed from T = 1.8 on. The early lead
// is the known lag of the experiment's first points (the gate was lifted by hand); wall friction
// (fluid.wall_viscosity) narrows the later gap but not the early one. So the test asserts: the
// early front's advance Z - 1 at T = 0.41 within 0.03 of the experiment's 0.11; the late front
// speed within 10%; the front never behind the experiment by more than 10% and never ahead by
// more than 25%.
#include <doctest/doctest.h>

#include <cmath>

#include "backend/backend_registry.hpp"
#include "test_setups.hpp"

using namespace mw;

TEST_CASE("dam break surge front follows Martin & Moyce") {
    const Real a = 0.2f, r0 = 0.01f, depth = 0.04f;
    SimulationSetup setup =
        test::fluid_in_box({0, 0, 0}, {5 * a, 2.5f * a, depth}, {0, 0, 0}, {a, 2 * a, depth}, r0, 0.001f);
    auto sim = create_openmp_simulation(setup, 0);
    const double T[] = {0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98, 2.20, 2.32, 2.51};
    const double Z[] = {1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56, 2.78, 3.00};
    const int samples = 10;
    const double time_scale = std::sqrt(2 * 9.81 / a);
    double simulated[samples], at_T[samples];
    HostParticles p;
    for (int k = 0; k < samples; ++k) {
        while (sim->time() * time_scale < T[k]) sim->step();
        sim->download(p);
        double front = 0;
        // Fluid centres beyond the walls' particle layer (outside the domain faces): a leak, long
        // before such a particle would count as lost (beyond the grid).
        long crossed_a_wall = 0;
        const Real wall = rest_density_wall_gap(r0, 2 * r0, r0 / 2, 1);
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            if (p.type[i] != kFluid) continue;
            const Vec3 x = p.position[i];
            front = std::max(front, double(x.x));
            crossed_a_wall += x.x < -wall || x.y < -wall || x.z < -wall || x.x > 5 * a + wall ||
                              x.y > 2.5f * a + wall || x.z > depth + wall;
        }
        CHECK(crossed_a_wall == 0);
        simulated[k] = (front + r0 / 2) / a;
        at_T[k] = sim->time() * time_scale;
        const double deviation = (simulated[k] - Z[k]) / Z[k];
        MESSAGE("T " << at_T[k] << ": Z " << simulated[k] << " (Martin & Moyce " << Z[k] << ", " << 100 * deviation
                     << "%)");
        CHECK(deviation > -0.10);
        CHECK(deviation < 0.25);
    }
    // The early front, as an advance: the column starts at Z = 1 (its front particle r0/2 inside
    // x = a), so a ratio test on Z itself would pass a column that never moved (Z = 1.00 is -9.9%).
    // The experiment's advance at T = 0.41 is 0.11. Allowed: 0.03 in Z, which is the front's
    // discreteness (the front is a particle centre + r0/2, known to about half a spacing,
    // r0 / (2a) = 0.025) plus the table's rounding to two decimals (0.005). The sample is taken at
    // the first step past T = 0.41 (ΔT < 0.01 late), which can only add to the advance, at most
    // about 0.005 at the early front's dZ/dT ≈ 0.5. Measured: 0.0995 (docs/solver.md: Z = 1.10).
    const double advance = simulated[0] - 1.0, experiment_advance = Z[0] - 1.0;
    MESSAGE("front advance at T " << at_T[0] << ": " << advance << " (Martin & Moyce " << experiment_advance << ")");
    CHECK(std::fabs(advance - experiment_advance) < 0.03);
    const double speed = (simulated[9] - simulated[5]) / (at_T[9] - at_T[5]);
    const double experiment_speed = (Z[9] - Z[5]) / (T[9] - T[5]);
    MESSAGE("front speed dZ/dT for T in [1.83, 2.51]: " << speed << " (Martin & Moyce " << experiment_speed << ")");
    CHECK(std::fabs(speed - experiment_speed) / experiment_speed < 0.10);
    CHECK(sim->last_report().lost_particles == 0);  // and none left the grid
}
