// Pressure sensors (algorithms/pressure_sensors.hpp): the load a pool at rest puts on its floor and
// its side walls is the hydrostatic one, ρ0 g × depth, although the fluid beside a wall holds about
// 1.5 times that pressure (docs/validation.md, "Fluid: walls").
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "simulation/factory.hpp"
#include "test_setups.hpp"
#include "../skip.hpp"

using namespace mw;

namespace {


// A 0.3 × 0.2 × 0.3 m pool (r0 0.02 m) with a sensor in the middle of its floor and three on one
// side wall, 4, 5.5 and 7 r0 deep, each 2 r0 across (the wall's particles, r0/2 apart, do not line
// up with the patches' edges).
std::string pool_scene(bool correction) {
    return std::string(R"({
  "domain": { "min": [0, 0, 0], "max": [0.3, 0.3, 0.3] },
  "fluid": { "spacing": 0.02, "viscosity": 0.01 },
  "solver": { "dt": 0.001 },
  "boundary": { "correction": )") + (correction ? "true" : "false") + R"( },
  "fluid_blocks": [ { "min": [0, 0, 0], "max": [0.3, 0.2, 0.3] } ],
  "pressure_sensors": [
    { "name": "floor", "center": [0.15, 0, 0.15], "size": 0.06 },
    { "name": "d4", "center": [0.3, 0.12, 0.15], "size": 0.04 },
    { "name": "d55", "center": [0.3, 0.09, 0.15], "size": 0.04 },
    { "name": "d7", "center": [0.3, 0.06, 0.15], "size": 0.04 } ]
})";
}

struct Loads {
    double floor = 0, d4 = 0, d55 = 0, d7 = 0;
};

// The readings averaged over every step from 0.8 s to 1.2 s (the pool still breathes after settling).
Loads settled_loads(bool correction) {
    const test::OneHostThread one;
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(build_setup(parse_scene_text(pool_scene(correction), "pool")), 1);
    while (sim->time() < 0.8) sim->step();
    Loads sum;
    int steps = 0;
    while (sim->time() < 1.2) {
        sim->step();
        const StepReport& r = sim->last_report();
        sum.floor += r.value("sensor_floor");
        sum.d4 += r.value("sensor_d4");
        sum.d55 += r.value("sensor_d55");
        sum.d7 += r.value("sensor_d7");
        ++steps;
    }
    return {sum.floor / steps, sum.d4 / steps, sum.d55 / steps, sum.d7 / steps};
}

}  // namespace

TEST_CASE("pressure sensors read the hydrostatic load of a pool at rest on its floor and a side wall, within 3%") {
    const double rho_g = 1000 * 9.81, level = 0.2;
    for (const bool correction : {true, false}) {
        CAPTURE(correction);
        const Loads l = settled_loads(correction);
        CHECK(l.floor / (rho_g * level) == doctest::Approx(1).epsilon(0.03));
        CHECK(l.d4 / (rho_g * 0.08) == doctest::Approx(1).epsilon(0.03));
        CHECK(l.d55 / (rho_g * 0.11) == doctest::Approx(1).epsilon(0.03));
        CHECK(l.d7 / (rho_g * 0.14) == doctest::Approx(1).epsilon(0.03));
        // Deeper, more load: the readings follow the depth, not one value.
        CHECK(l.d4 < l.d55);
        CHECK(l.d55 < l.d7);
    }
}

TEST_CASE("a pressure sensor on a face without walls is refused, naming it") {
    std::string scene = pool_scene(true);
    scene.replace(scene.find("\"correction\": true"), std::string("\"correction\": true").size(), "\"walls\": false");
    CHECK_THROWS_WITH_AS(create_openmp_simulation(build_setup(parse_scene_text(scene, "pool")), 1),
                         doctest::Contains("pressure_sensors: floor has no wall particle"), InputError);
}

TEST_CASE("CUDA and OpenMP read the same wall loads: the pool, 200 steps") {
    if (!cuda_backend_info().available) {
        MW_SKIP(cuda_backend_info().description);
        return;
    }
    const test::OpenmpAndCuda runs =
        test::run_openmp_and_cuda(build_setup(parse_scene_text(pool_scene(true), "pool")), 200);
    for (const char* column : {"sensor_floor", "sensor_d4", "sensor_d55", "sensor_d7"}) {
        CAPTURE(column);
        // Float sums in another order: within 0.5% of the floor's hydrostatic load.
        CHECK(std::fabs(runs.openmp_report.value(column) - runs.cuda_report.value(column)) < 0.005 * 1000 * 9.81 * 0.2);
    }
}
