// Melting in 2D (algorithms/melting.hpp on a plane lattice): an outline's lattice melts from the
// outside in, one ring a step, every particle staying in the plane; a block of ice in a warm 2D
// pool melts gradually, and what melts joins the water.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "apps/scene.hpp"
#include "apps/scene_builder.hpp"
#include "simulation/factory.hpp"
#include "test_setups.hpp"

using namespace mw;

namespace {
long count_type(const HostParticles& p, std::uint8_t type) { return std::count(p.type.begin(), p.type.end(), type); }

// A square of ice 0.1 m across at r0 0.02 m in a 2D domain, 30 K over its melting point, no
// gravity and no latent heat (`pool`: none); or at -1 °C with a little latent heat in a warm
// pool under gravity.
std::string ice_scene(bool pool) {
    return std::string(R"({
  "name": "melt_2d", "dimensions": 2,
  "domain": { "min": [0, 0], "max": [0.4, 0.4] },
  "gravity": )") + (pool ? "[0, -9.81]" : "[0, 0]") + R"(,
  "fluid": { "spacing": 0.02, "temperature": 60, "thermal_diffusivity": 0.005 },
  "solver": { "dt": 0.002 },
  "heat": { "enabled": true },
  )" + (pool ? R"("fluid_blocks": [ { "min": [0, 0], "max": [0.4, 0.16] } ],)" : "") + R"(
  "objects": [ { "name": "ice", "mesh": { "procedural": "rectangle:x=0.1,y=0.1" },
                 "transform": { "translation": [0.2, )" + (pool ? "0.2" : "0.2") + R"(] }, "kind": "elastic",
                 "density": 900, "temperature": )" + (pool ? "-1" : "30") + R"(, "heat_capacity": 1.9e6,
                 "thermal_diffusivity": 0.005, "melting_point": 0, "latent_heat": )" + (pool ? "2000" : "0") + R"( } ]
})";
}
}  // namespace

TEST_CASE("2D melting: an outline's lattice melts from the outside in, one ring a step, in the plane") {
    const SimulationSetup setup = build_setup(parse_scene_text(ice_scene(false), "melt_2d.json"));
    REQUIRE(setup.solids.size() == 1);
    const long total = long(setup.solids[0].ibp.size());
    const long side = std::lround(std::sqrt(double(total)));
    REQUIRE(side * side == total);
    REQUIRE(side >= 4);
    // The lattice's outer ring is SBPs, its inside IBPs (8 one-ring neighbours in the plane).
    long surface = 0;
    for (std::uint32_t i : setup.solids[0].ibp) surface += setup.type[i] == kSurfaceBoundary;
    CHECK(surface == total - (side - 2) * (side - 2));
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 1);
    long melted = 0;
    for (long inner = side - 2, step = 1; melted < total; inner -= 2, ++step) {
        const long solid_after = inner > 0 ? inner * inner : 0;
        const HostParticles p = test::run_steps(*sim, 1);
        melted = sim->last_report().value("melted");
        INFO("step " << step);
        CHECK(melted == total - solid_after);
        CHECK(count_type(p, kFluid) == total - solid_after);
        const long inside = inner > 2 ? (inner - 2) * (inner - 2) : 0;
        CHECK(count_type(p, kInnerBoundary) == inside);
        CHECK(count_type(p, kSurfaceBoundary) == solid_after - inside);
        for (std::size_t i = 0; i < p.position.size(); ++i) REQUIRE(p.position[i].z == 0);
        REQUIRE(step < 10);
    }
    test::run_steps(*sim, 3);
    CHECK(sim->counts().by_type[kFluid] == total);
}

TEST_CASE("2D melting: ice in a warm pool melts gradually, to the last particle, and what melts joins the water") {
    const SimulationSetup setup = build_setup(parse_scene_text(ice_scene(true), "melt_pool_2d.json"));
    const long ice = long(setup.solids[0].ibp.size());
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 1);
    const long fluid_at_start = sim->counts().by_type[kFluid];
    long previous = 0, steps_with_melting = 0, first = 0, last = 0;
    for (int step = 1; step <= 400 && previous < ice; ++step) {
        sim->step();
        const long melted = sim->last_report().value("melted");
        REQUIRE(melted >= previous);
        if (melted > previous) {
            ++steps_with_melting;
            last = step;
            if (first == 0) first = step;
        }
        previous = melted;
        REQUIRE(sim->last_report().lost_particles == 0);
    }
    HostParticles p;
    sim->download(p);
    MESSAGE(previous << " of " << ice << " particles melted, on " << steps_with_melting << " steps from step " << first
                     << " to " << last);
    CHECK(previous == ice);
    CHECK(steps_with_melting > 3);  // gradually: layer by layer as the heat arrives
    CHECK(last - first > 20);
    CHECK(count_type(p, kFluid) == fluid_at_start + ice);
    for (std::size_t i = 0; i < p.position.size(); ++i) {
        REQUIRE(std::isfinite(double(p.position[i].y)));
        REQUIRE(p.position[i].z == 0);
    }
}
