// What is particular to the plane: a 2D scene's boundaries have no faces normal to z. A 2D dam
// break strikes a static box standing on the floor (its outline sampled as in 3D), and static
// objects (a disc, a thin plate) held off the floor; the walls', the box's and the objects'
// velocity–position correction must hold the fluid at its band in the plane without ever pushing
// a particle off it; pressure sensors on a 2D pool's floor and side read the water's weight.
// (The fluid alone in 2D: test_hydrostatic.cpp, test_dam_break.cpp.)
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>

#include "algorithms/pcisph_delta.hpp"
#include "algorithms/sph_kernels.hpp"
#include "algorithms/wall_contact.hpp"
#include "apps/scene.hpp"
#include "apps/scene_builder.hpp"
#include "simulation/factory.hpp"

using namespace mw;

namespace {
// A 0.4 x 0.8 m column at r0 0.02 m collapsing onto an obstacle downstream, CFL steps as the
// scenes run them. The obstacle: the scene's entry for it and its signed distance (negative
// inside); a fluid centre at or below `inside_at` counts as inside.
struct Obstacle {
    std::string entry;
    std::function<double(double, double)> distance;
    double inside_at = 0;
};

// The signed distance to the rectangle [x0, x1] x [y0, y1].
double rectangle_distance(double x, double y, double x0, double x1, double y0, double y1) {
    const double dx = std::max(x0 - x, x - x1), dy = std::max(y0 - y, y - y1);
    return dx < 0 && dy < 0 ? std::max(dx, dy) : std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
}

// A 0.2 m square static box on the floor, 0.5 m downstream.
Obstacle static_box() {
    return {R"("static_boxes": [ { "min": [0.9, 0], "max": [1.1, 0.2] } ])",
            [](double x, double y) { return rectangle_distance(x, y, 0.9, 1.1, 0.0, 0.2); }};
}

// Static objects 1 m downstream, 0.1-0.4 m above the floor, so that the surge runs under and
// over them: a disc of radius 0.1 m (its outline a 64-gon, whose flats lie 0.0012 of the radius
// inside the circle) centred 0.25 m up, or a plate one r0 thick and 0.3 m tall.
Obstacle static_object(const std::string& procedural, std::function<double(double, double)> distance, double inside_at) {
    return {R"("objects": [ { "name": "obstacle", "kind": "static", "mesh": { "procedural": ")" + procedural +
                R"(" }, "transform": { "translation": [1.0, 0.25] } } ])",
            std::move(distance), inside_at};
}
Obstacle disc() {
    return static_object("circle:radius=0.1", [](double x, double y) { return std::hypot(x - 1.0, y - 0.25) - 0.1; },
                         -0.0012 * 0.1);
}
Obstacle plate() {
    return static_object("rectangle:x=0.02,y=0.3",
                         [](double x, double y) { return rectangle_distance(x, y, 0.99, 1.01, 0.1, 0.4); }, 0);
}

std::string dam_against(const Obstacle& obstacle, bool correction) {
    return std::string(R"({
  "name": "dam_obstacle_2d",
  "dimensions": 2,
  "domain": { "min": [0, 0], "max": [1.6, 1.0] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.002, "dt_mode": "cfl" },
  "boundary": { "correction": )") +
           (correction ? "true" : "false") + R"( },
  "fluid_blocks": [ { "min": [0, 0], "max": [0.4, 0.8] } ],
  )" + obstacle.entry + R"(
})";
}

struct DamRun {
    double closest = 1e9;  // the closest fluid centre came to the obstacle, m
    double largest_z = 0;
    long inside = 0, lost = 0;
};

DamRun run_against(const Obstacle& obstacle, bool correction, double seconds) {
    const SimulationSetup setup = build_setup(parse_scene_text(dam_against(obstacle, correction), "dam_obstacle_2d.json"));
    auto sim = create_openmp_simulation(setup, 1);
    DamRun out;
    HostParticles p;
    while (sim->time() < seconds) {
        sim->step();
        sim->download(p);
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            out.largest_z = std::max(out.largest_z, std::fabs(double(p.position[i].z)));
            if (p.type[i] != kFluid) continue;
            const double d = obstacle.distance(p.position[i].x, p.position[i].y);
            out.closest = std::min(out.closest, d);
            out.inside += d <= obstacle.inside_at;
        }
        out.lost = std::max(out.lost, sim->last_report().lost_particles);
    }
    return out;
}
}  // namespace

TEST_CASE("2D: a dam break against a static box keeps its fluid at the box's band and in the plane") {
    const double r0 = 0.02;
    const SimulationSetup setup = build_setup(parse_scene_text(dam_against(static_box(), true), "dam_obstacle_2d.json"));
    REQUIRE(setup.params.boundary.static_boxes.size() == 1);
    const double band = contact_box(setup.params.boundary.static_boxes[0], Real(r0), 2).contact;
    const DamRun with = run_against(static_box(), true, 1.5);
    const DamRun without = run_against(static_box(), false, 1.5);
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

TEST_CASE("2D: a dam break against static objects keeps its fluid at their band and in the plane") {
    const double r0 = 0.02;
    const SimulationSetup setup = build_setup(parse_scene_text(dam_against(disc(), true), "dam_obstacle_2d.json"));
    // The object's distance grid: two equal layers either side of the plane (sampling/outline_distance.hpp).
    REQUIRE(setup.params.boundary.static_objects.size() == 1);
    const ContactField& field = setup.params.boundary.static_objects[0];
    CHECK(field.field.nz == 2);
    const double band = kStaticObjectContact * r0;
    const DamRun round = run_against(disc(), true, 1.5);
    const DamRun thin = run_against(plate(), true, 1.5);
    const DamRun thin_without = run_against(plate(), false, 1.5);
    MESSAGE("closest fluid centre: the disc " << round.closest / r0 << " r0, the plate " << thin.closest / r0
                                              << " r0 with the correction (band " << band / r0 << " r0), "
                                              << thin_without.closest / r0 << " r0 without");
    for (const DamRun* run : {&round, &thin, &thin_without}) {
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
