// What is particular to the plane: a 2D scene's boundaries have no faces normal to z. A 2D dam
// break strikes a static box standing on the floor (its outline sampled as in 3D); the walls' and
// the box's velocity–position correction must hold the fluid at its band in the plane without
// ever pushing a particle off it; pressure sensors on a 2D pool's floor and side read the water's weight.
// (The fluid alone in 2D: test_hydrostatic.cpp, test_dam_break.cpp.)
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "algorithms/pcisph_delta.hpp"
#include "algorithms/sph_kernels.hpp"
#include "algorithms/wall_contact.hpp"
#include "apps/scene.hpp"
#include "apps/scene_builder.hpp"
#include "simulation/factory.hpp"

using namespace mw;

namespace {
// A 0.4 x 0.8 m column at r0 0.02 m collapsing onto a 0.2 m square box 0.5 m downstream, CFL steps
// as the scenes run them.
std::string dam_against_box(bool correction) {
    return std::string(R"({
  "name": "dam_box_2d",
  "dimensions": 2,
  "domain": { "min": [0, 0], "max": [1.6, 1.0] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.002, "dt_mode": "cfl" },
  "boundary": { "correction": )") +
           (correction ? "true" : "false") + R"( },
  "fluid_blocks": [ { "min": [0, 0], "max": [0.4, 0.8] } ],
  "static_boxes": [ { "min": [0.9, 0], "max": [1.1, 0.2] } ]
})";
}

struct BoxRun {
    double closest = 1e9;  // the closest fluid centre came to the box, m
    double largest_z = 0;
    long inside = 0, lost = 0;
};

BoxRun run_against_box(bool correction, double seconds) {
    const SimulationSetup setup = build_setup(parse_scene_text(dam_against_box(correction), "dam_box_2d.json"));
    auto sim = create_openmp_simulation(setup, 1);
    BoxRun out;
    HostParticles p;
    while (sim->time() < seconds) {
        sim->step();
        sim->download(p);
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            out.largest_z = std::max(out.largest_z, std::fabs(double(p.position[i].z)));
            if (p.type[i] != kFluid) continue;
            const double x = p.position[i].x, y = p.position[i].y;
            const double dx = x - std::clamp(x, 0.9, 1.1), dy = y - std::clamp(y, 0.0, 0.2);
            out.closest = std::min(out.closest, std::sqrt(dx * dx + dy * dy));
            out.inside += dx == 0 && dy == 0;
        }
        out.lost = std::max(out.lost, sim->last_report().lost_particles);
    }
    return out;
}
}  // namespace

TEST_CASE("2D: a dam break against a static box keeps its fluid at the box's band and in the plane") {
    const double r0 = 0.02;
    const SimulationSetup setup = build_setup(parse_scene_text(dam_against_box(true), "dam_box_2d.json"));
    REQUIRE(setup.params.boundary.static_boxes.size() == 1);
    const double band = contact_box(setup.params.boundary.static_boxes[0], Real(r0), 2).contact;
    const BoxRun with = run_against_box(true, 1.5);
    const BoxRun without = run_against_box(false, 1.5);
    MESSAGE("closest fluid centre to the box: " << with.closest / r0 << " r0 with the correction (band "
                                                << band / r0 << " r0), " << without.closest / r0 << " r0 without");
    CHECK(with.inside == 0);
    CHECK(without.inside == 0);
    CHECK(with.lost == 0);
    CHECK(without.lost == 0);
    CHECK(with.largest_z == 0);
    CHECK(without.largest_z == 0);
    // The correction puts fluid moving into the box back at its band; a particle inside the band
    // that is leaving it is left where it is, so the band holds to within 10% (measured 0.922 r0
    // for a band of 0.935 r0). Without it the Akinci layer alone lets the surge come closer
    // (measured 0.606 r0).
    CHECK(with.closest > 0.9 * band);
    CHECK(without.closest < 0.9 * band);
}

namespace {
// The same dam against a static object 1 m downstream, 0.1-0.4 m above the floor, so that the
// surge runs under and over it: a disc of radius 0.1 m (its outline a 64-gon) centred 0.25 m up,
// or a plate one r0 thick and 0.3 m tall. `distance`: the signed distance to the object.
struct StaticShape {
    const char* procedural;
    std::function<double(double, double)> distance;
};
StaticShape disc() {
    return {"circle:radius=0.1", [](double x, double y) { return std::hypot(x - 1.0, y - 0.25) - 0.1; }};
}
StaticShape plate() {
    return {"rectangle:x=0.02,y=0.3", [](double x, double y) {
                const double dx = std::fabs(x - 1.0) - 0.01, dy = std::fabs(y - 0.25) - 0.15;
                return dx < 0 && dy < 0 ? std::max(dx, dy) : std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
            }};
}
std::string dam_against_object(const StaticShape& shape, bool correction) {
    return std::string(R"({
  "name": "dam_object_2d",
  "dimensions": 2,
  "domain": { "min": [0, 0], "max": [1.6, 1.0] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.002, "dt_mode": "cfl" },
  "boundary": { "correction": )") +
           (correction ? "true" : "false") + R"( },
  "fluid_blocks": [ { "min": [0, 0], "max": [0.4, 0.8] } ],
  "objects": [ { "name": "obstacle", "kind": "static", "mesh": { "procedural": ")" + shape.procedural + R"(" },
                 "transform": { "translation": [1.0, 0.25] } } ]
})";
}

BoxRun run_against_object(const StaticShape& shape, bool correction, double seconds) {
    const SimulationSetup setup = build_setup(parse_scene_text(dam_against_object(shape, correction), "dam_object_2d.json"));
    auto sim = create_openmp_simulation(setup, 1);
    BoxRun out;
    HostParticles p;
    while (sim->time() < seconds) {
        sim->step();
        sim->download(p);
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            out.largest_z = std::max(out.largest_z, std::fabs(double(p.position[i].z)));
            if (p.type[i] != kFluid) continue;
            const double d = shape.distance(p.position[i].x, p.position[i].y);
            out.closest = std::min(out.closest, d);
            out.inside += d < -0.0012 * 0.1;  // the 64-gon's flats lie 0.0012 of the radius inside the circle
        }
        out.lost = std::max(out.lost, sim->last_report().lost_particles);
    }
    return out;
}
}  // namespace

TEST_CASE("2D: a dam break against static objects keeps its fluid at their band and in the plane") {
    const double r0 = 0.02;
    const SimulationSetup setup = build_setup(parse_scene_text(dam_against_object(disc(), true), "dam_object_2d.json"));
    // The object's distance grid: two equal layers either side of the plane (sampling/outline_distance.hpp).
    REQUIRE(setup.params.boundary.static_objects.size() == 1);
    const ContactField& field = setup.params.boundary.static_objects[0];
    CHECK(field.field.nz == 2);
    const double band = kStaticObjectContact * r0;
    const BoxRun round = run_against_object(disc(), true, 1.5);
    const BoxRun thin = run_against_object(plate(), true, 1.5);
    const BoxRun thin_without = run_against_object(plate(), false, 1.5);
    MESSAGE("closest fluid centre: the disc " << round.closest / r0 << " r0, the plate " << thin.closest / r0
                                              << " r0 with the correction (band " << band / r0 << " r0), "
                                              << thin_without.closest / r0 << " r0 without");
    for (const BoxRun* run : {&round, &thin, &thin_without}) {
        CHECK(run->inside == 0);
        CHECK(run->lost == 0);
        CHECK(run->largest_z == 0);
    }
    // The disc's boundary particles alone keep this surge farther off than the band (0.52 r0
    // measured, with and without the correction, as a sphere's do in 3D: test_object_contact.cpp).
    CHECK(round.closest > 0.9 * band);
    // Around the plate's corners the surge comes closer: the correction holds it at 0.37 r0
    // (the band is thinner at convex corners, docs/solver.md), the plate's particles alone at
    // 0.19 r0 (measured).
    CHECK(thin.closest > 0.75 * band);
    CHECK(thin_without.closest < 0.6 * band);
}

namespace {
// A 2D pool 0.4 m wide and 0.3 m deep at r0 0.02 m, μ 0.05 Pa·s, CFL steps up to 2 ms, with a
// sensor on the floor's middle (0.08 m) and two on the left wall (0.04 m) 0.15 and 0.25 m deep.
const char* kPool2d = R"({
  "name": "pool_2d", "dimensions": 2,
  "domain": { "min": [0, 0], "max": [0.4, 0.4] },
  "fluid": { "spacing": 0.02, "viscosity": 0.05 },
  "solver": { "dt": 0.002, "dt_mode": "cfl" },
  "fluid_blocks": [ { "min": [0, 0], "max": [0.4, 0.3] } ],
  "pressure_sensors": [ { "name": "floor", "center": [0.2, 0], "size": 0.08 },
                        { "name": "wall_15", "center": [0, 0.15], "size": 0.04 },
                        { "name": "wall_05", "center": [0, 0.05], "size": 0.04 } ]
})";
}  // namespace

TEST_CASE("2D: pressure sensors on the floor and a side wall read the weight of the water above them") {
    const SimulationSetup setup = build_setup(parse_scene_text(kPool2d, "pool_2d.json"));
    REQUIRE(setup.pressure_sensors.size() == 3);
    auto sim = create_openmp_simulation(setup, 1);
    const double g = 9.81, width = 0.4;
    // A particle's mass per unit depth: ρ0 over the 2D prototype lattice's Σ W (pcisph_delta.hpp).
    const double mass = with_kernel(KernelKind::kCubicSpline, 2, setup.params.fluid.support_radius, [&](const auto& kernel) {
        return double(setup.params.fluid.rest_density) / prototype_sums(kernel, 0.02, 2).sum_W;
    });
    double floor = 0, wall_15 = 0, wall_05 = 0, above_15 = 0, above_05 = 0, fluid_weight = 0;
    long steps = 0;
    HostParticles p;
    while (sim->time() < 1.2) {
        sim->step();
        if (sim->time() < 0.8) continue;
        const StepReport& r = sim->last_report();
        floor += r.value("sensor_floor"), wall_15 += r.value("sensor_wall_15"), wall_05 += r.value("sensor_wall_05");
        // The weight per unit length of the water above each wall sensor's centre, and of all of it.
        sim->download(p);
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            if (p.type[i] != kFluid) continue;
            fluid_weight += mass * g / width;
            if (p.position[i].y > 0.15) above_15 += mass * g / width;
            if (p.position[i].y > 0.05) above_05 += mass * g / width;
        }
        ++steps;
    }
    REQUIRE(steps > 50);
    floor /= double(steps), wall_15 /= double(steps), wall_05 /= double(steps);
    fluid_weight /= double(steps), above_15 /= double(steps), above_05 /= double(steps);
    MESSAGE("2D sensors over the weight above them: floor " << floor / fluid_weight << ", wall 0.15 m deep "
                                                            << wall_15 / above_15 << ", 0.25 m deep " << wall_05 / above_05);
    CHECK(floor / fluid_weight == doctest::Approx(1).epsilon(0.03));
    CHECK(wall_15 / above_15 == doctest::Approx(1).epsilon(0.05));
    CHECK(wall_05 / above_05 == doctest::Approx(1).epsilon(0.05));
}
