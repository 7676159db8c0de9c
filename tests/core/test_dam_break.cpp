// Dam break against Martin & Moyce (1952): column a wide and 2a high, front Z = x/a against
// T = t sqrt(2g/a) (table in METHOD.md), at r0 = a/20 with free-slip walls and no tuning.
//
// The simulated column is released at t = 0 in one instant; the experiment's was not: it was held
// by a barrier whose removal took a time of its own, and its first points lag an instantaneous
// release by that much. Compared on the raw clock, this solver and others (docs/solver.md) lead
// the table by 10-20% for T around 1, and the Lethe project's validation of the same table
// shifts the simulated clock by ΔT0 = 0.175 (examples/multiphysics/dam-break/dam-break-2d.py,
// `time_correction`). So the test checks three things:
//  - the criterion on the release-corrected clock: every point for T <= 2.51 within 10%
//    of the table, comparing the table's Z at T with the simulated front at T - 0.175 (Lethe's
//    value, not fitted here; measured: within 7.7%);
//  - the raw clock, with no correction: the front never behind the table by more than 10% and
//    never ahead by more than 25% (measured: -1.2% to +20.1%); its early advance (Z - 1 at
//    T = 0.41) within 0.03 of the table's; its late speed dZ/dT within 10%;
//  - no fluid crosses a wall.
// The offset that fits the table best (least squares over 0 <= ΔT0 <= 0.5) is printed beside
// Lethe's; it is 0.265 here (0.25 at r0 = a/40) and not asserted.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "backend/backend_registry.hpp"
#include "test_setups.hpp"

using namespace mw;

namespace {

// The simulated front Z(T), one sample per step from the start, linearly interpolated between
// them (before the first step the column's front is at Z = 1).
struct FrontHistory {
    std::vector<double> T{0.0}, Z{1.0};
    double at(double t) const {
        if (t <= T.front()) return Z.front();
        std::size_t k = 1;
        while (k + 1 < T.size() && T[k] < t) ++k;
        const double w = (t - T[k - 1]) / (T[k] - T[k - 1]);
        return Z[k - 1] + w * (Z[k] - Z[k - 1]);
    }
};

}  // namespace

TEST_CASE("dam break surge front follows Martin & Moyce") {
    const Real a = 0.2f, r0 = 0.01f, depth = 0.04f;
    SimulationSetup setup =
        test::fluid_in_box({0, 0, 0}, {5 * a, 2.5f * a, depth}, {0, 0, 0}, {a, 2 * a, depth}, r0, 0.001f);
    auto sim = create_openmp_simulation(setup, 0);
    const double T[] = {0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98, 2.20, 2.32, 2.51};
    const double Z[] = {1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56, 2.78, 3.00};
    const int samples = 10;
    const double release_delay = 0.175;  // ΔT0 of Lethe's comparison with the same table
    const double time_scale = std::sqrt(2 * 9.81 / a);
    const Real wall = rest_density_wall_gap(r0, 2 * r0, r0 / 2, 1);

    FrontHistory front;
    HostParticles p;
    long crossed_a_wall = 0;
    while (front.T.back() < T[samples - 1]) {
        sim->step();
        sim->download(p);
        double x_front = 0;
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            if (p.type[i] != kFluid) continue;
            const Vec3 x = p.position[i];
            x_front = std::max(x_front, double(x.x));
            // Fluid centres beyond the walls' particle layer (outside the domain faces): a leak,
            // long before such a particle would count as lost (beyond the grid).
            crossed_a_wall += x.x < -wall || x.y < -wall || x.z < -wall || x.x > 5 * a + wall ||
                              x.y > 2.5f * a + wall || x.z > depth + wall;
        }
        front.T.push_back(sim->time() * time_scale);
        front.Z.push_back((x_front + r0 / 2) / a);  // a particle centre + r0/2: the fluid's edge
    }
    CHECK(crossed_a_wall == 0);
    CHECK(sim->last_report().lost_particles == 0);  // and none left the grid

    // The release-corrected clock: the 10% on every point.
    double worst_corrected = 0;
    for (int k = 0; k < samples; ++k) {
        const double raw = (front.at(T[k]) - Z[k]) / Z[k];
        const double corrected = (front.at(T[k] - release_delay) - Z[k]) / Z[k];
        MESSAGE("T " << T[k] << ": Martin & Moyce Z " << Z[k] << "; simulated " << front.at(T[k]) << " (" << 100 * raw
                     << "%), released " << release_delay << " later " << front.at(T[k] - release_delay) << " ("
                     << 100 * corrected << "%)");
        CHECK(std::fabs(corrected) < 0.10);
        CHECK(raw > -0.10);
        CHECK(raw < 0.25);
        worst_corrected = std::max(worst_corrected, std::fabs(corrected));
    }
    MESSAGE("largest deviation with the release delay " << release_delay << ": " << 100 * worst_corrected << "%");

    double best_delay = 0, best_sum = 1e300;
    for (int step = 0; step <= 100; ++step) {
        const double delay = 0.005 * step;
        double sum = 0;
        for (int k = 0; k < samples; ++k) sum += std::pow((front.at(T[k] - delay) - Z[k]) / Z[k], 2);
        if (sum < best_sum) best_sum = sum, best_delay = delay;
    }
    MESSAGE("release delay that fits the table best: " << best_delay << " (rms deviation "
                                                        << 100 * std::sqrt(best_sum / samples) << "%)");

    // The early front, as an advance on the raw clock: the column starts at Z = 1 (its front
    // particle r0/2 inside x = a), so a ratio test on Z itself would pass a column that never moved
    // (Z = 1.00 is -9.9%). The experiment's advance at T = 0.41 is 0.11. Allowed: 0.03 in Z, which
    // is the front's discreteness (a particle centre + r0/2, known to about half a spacing,
    // r0 / (2a) = 0.025) plus the table's rounding to two decimals (0.005). Measured: 0.097.
    const double advance = front.at(T[0]) - 1.0, experiment_advance = Z[0] - 1.0;
    MESSAGE("front advance at T " << T[0] << ": " << advance << " (Martin & Moyce " << experiment_advance << ")");
    CHECK(std::fabs(advance - experiment_advance) < 0.03);
    const double speed = (front.at(T[9]) - front.at(T[5])) / (T[9] - T[5]);
    const double experiment_speed = (Z[9] - Z[5]) / (T[9] - T[5]);
    MESSAGE("front speed dZ/dT for T in [1.83, 2.51]: " << speed << " (Martin & Moyce " << experiment_speed << ")");
    CHECK(std::fabs(speed - experiment_speed) / experiment_speed < 0.10);
}
