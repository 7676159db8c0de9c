// Cloth (docs/cloth.md): one layer of nodes on an open sheet, shape-matched over their w-rings,
// met by the fluid from both sides; its stretch against the step; water held on it from above
// and from below; a light cloth under water with and without its nodes' answer inside PCISPH;
// bad sheets and pins refused.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/lsm_regions.hpp"
#include "common/errors.hpp"
#include "simulation/factory.hpp"
#include "test_setups.hpp"
#include "../skip.hpp"

using namespace mw;

namespace {

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", v);
    return text;
}

// A 0.4 m x 0.2 m cloth (21 x 11 nodes) hung by its two short edges, alone, at fixed steps `dt`.
std::string hammock(double dt) {
    return R"({
  "domain": { "min": [0, 0, 0], "max": [0.5, 0.5, 0.5] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": )" + number(dt) + R"(, "dt_mode": "fixed" },
  "boundary": { "walls": false },
  "objects": [ { "name": "cloth", "mesh": { "procedural": "sheet:x=0.4,z=0.2,nx=20,nz=10" },
    "transform": { "translation": [0.25, 0.4, 0.25] }, "kind": "cloth", "density": 300,
    "lsm": { "alpha": 0.5, "damping": 5, "body_damping": 5 },
    "pinned": { "boxes": [ { "min": [0.04, 0.39, 0.1], "max": [0.06, 0.41, 0.4] },
                           { "min": [0.44, 0.39, 0.1], "max": [0.46, 0.41, 0.4] } ] } } ]
})";
}

// A 0.4 m square cloth at y = 0.3 pinned along its rim, under 4 layers of water (a basin), or
// with gravity reversed and the water under it (`from_below`): the same scene mirrored, met on
// the sheet's other side (its normal is +y).
std::string basin(double density, bool from_below, double substep, bool water = true) {
    const std::string block = from_below ? R"({ "min": [0.07, 0.205, 0.07], "max": [0.43, 0.285, 0.43] })"
                                         : R"({ "min": [0.07, 0.315, 0.07], "max": [0.43, 0.395, 0.43] })";
    return R"({
  "domain": { "min": [0, 0, 0], "max": [0.5, 0.6, 0.5] },
  "gravity": [0, )" + std::string(from_below ? "9.81" : "-9.81") + R"(, 0],
  "fluid": { "spacing": 0.02, "viscosity": 0.01 },
  "solver": { "dt": 0.01, "dt_mode": "cfl", "solid_substep": )" + number(substep) + R"( },
  "objects": [ { "name": "cloth", "mesh": { "procedural": "sheet:x=0.4,z=0.4,nx=20,nz=20" },
    "transform": { "translation": [0.25, 0.3, 0.25] }, "kind": "cloth", "density": )" + number(density) + R"(,
    "lsm": { "alpha": 0.5, "body_damping": 2 },
    "pinned": { "boxes": [ { "min": [0.04, 0.29, 0.04], "max": [0.46, 0.31, 0.06] },
                           { "min": [0.04, 0.29, 0.44], "max": [0.46, 0.31, 0.46] },
                           { "min": [0.04, 0.29, 0.04], "max": [0.06, 0.31, 0.46] },
                           { "min": [0.44, 0.29, 0.04], "max": [0.46, 0.31, 0.46] } ] } } ],
  "fluid_blocks": [ )" + (water ? block : std::string()) + R"( ]
})";
}

SimulationSetup setup_of(const std::string& json, const std::vector<std::string>& overrides = {}) {
    return build_setup(parse_scene_text(json, "cloth test", overrides));
}

// The cloth's lowest (highest, `upward`) node's distance from y0.
double sag(const HostParticles& p, double y0, bool upward = false) {
    double s = 0;
    for (std::size_t i = 0; i < p.type.size(); ++i)
        if (p.type[i] == kInnerBoundary) s = std::max(s, upward ? double(p.position[i].y) - y0 : y0 - double(p.position[i].y));
    return s;
}

double fastest(const HostParticles& p, std::uint8_t type) {
    double v = 0;
    for (std::size_t i = 0; i < p.type.size(); ++i)
        if (p.type[i] == type) v = std::max(v, double(norm(p.velocity[i])));
    return v;
}

// Fluid runs from one side of the cloth to the other: each fluid particle over the cloth's inner
// part (x, z in (0.11, 0.39), away from the rim the water spills over) is on the water's side
// when it lies beyond the nearest node in x and z (the same index in every download: the host
// order is the scene's). A particle seen on the water's side and next on the other, still over
// the inner part, has crossed.
struct CrossingCount {
    bool upward = false;
    std::vector<int> side;
    long crossings = 0;
    void look(const HostParticles& p) {
        std::vector<Vec3> nodes;
        for (std::size_t i = 0; i < p.type.size(); ++i)
            if (p.type[i] == kInnerBoundary) nodes.push_back(p.position[i]);
        side.resize(p.type.size(), 0);
        for (std::size_t i = 0; i < p.type.size(); ++i) {
            const Vec3 x = p.position[i];
            int now = 0;
            if (p.type[i] == kFluid && x.x > 0.11 && x.x < 0.39 && x.z > 0.11 && x.z < 0.39) {
                std::size_t nearest = 0;
                double best = 1e30;
                for (std::size_t k = 0; k < nodes.size(); ++k) {
                    const double d = std::hypot(double(x.x - nodes[k].x), double(x.z - nodes[k].z));
                    if (d < best) best = d, nearest = k;
                }
                const double above = double(x.y - nodes[nearest].y);
                now = (upward ? -above : above) > 0 ? 1 : -1;
            }
            if (side[i] > 0 && now < 0) ++crossings;
            side[i] = now;
        }
    }
};

// Runs to `until` in slices of 5 ms, counting crossings after each.
HostParticles run_counting(Simulation& sim, double until, CrossingCount& count) {
    HostParticles p;
    for (double t = 0.005; t <= until + 1e-9; t += 0.005) {
        while (sim.time() < t - 1e-9) sim.step();
        sim.download(p);
        count.look(p);
    }
    return p;
}

}  // namespace

TEST_CASE("A cloth's nodes are its sheet's vertices, each weighing its share of the sheet, and its regions are their w-rings") {
    const SimulationSetup setup = setup_of(R"({
  "domain": { "min": [0, 0, 0], "max": [0.5, 0.5, 0.5] },
  "fluid": { "spacing": 0.02 },
  "objects": [ { "name": "cloth", "mesh": { "procedural": "sheet:x=0.2,z=0.2,nx=10,nz=10" },
    "transform": { "translation": [0.25, 0.25, 0.25] }, "kind": "cloth", "density": 300 } ]
})");
    REQUIRE(setup.solids.size() == 1);
    const SolidSetup& cloth = setup.solids[0];
    CHECK(cloth.ibp.size() == 121);  // a grid at spacing r0 keeps its vertices
    CHECK(cloth.gp.size() == 121);
    CHECK(cloth.sbp.size() > 121);   // sampled on the triangles, about 3 per r0^2
    double mass = 0;
    for (Real m : cloth.ibp_mass) mass += m;
    CHECK(mass == doctest::Approx(300 * 0.02 * 0.2 * 0.2).epsilon(1e-5));  // density x r0 x area
    const LsmHostLayout L = build_lsm_layout(setup);
    REQUIRE(L.sbp_sides.size() == L.sbp_count);
    CHECK(std::all_of(L.sbp_sides.begin(), L.sbp_sides.end(), [](std::uint8_t t) { return t == 1; }));
    // Each node's region is the nodes within w = 2 edges; membership is symmetric, so a node's
    // regions are its region's members.
    std::size_t centre = 0, corner = 0;
    for (std::size_t s = 0; s < L.ibp_count; ++s) {
        const Vec3 x = L.ibp_rest[s];
        if (std::fabs(x.x - 0.25f) < 1e-4f && std::fabs(x.z - 0.25f) < 1e-4f) centre = s;
        if (std::fabs(x.x - 0.15f) < 1e-4f && std::fabs(x.z - 0.15f) < 1e-4f) corner = s;
    }
    const auto members = [&](std::size_t r) {
        return std::vector<std::uint32_t>(L.member_index.begin() + L.region_offsets[r], L.member_index.begin() + L.region_end[r]);
    };
    const std::vector<std::uint32_t> middle = members(centre);
    // Each quad of the sheet is split along one diagonal, so an inner vertex has 6 edges: its
    // 2-ring holds 1 + 6 + 12 nodes.
    CHECK(middle.size() == 19);
    CHECK(members(corner).size() < middle.size());
    for (std::uint32_t m : middle) {
        const std::vector<std::uint32_t> back = members(m);
        CHECK(std::binary_search(back.begin(), back.end(), std::uint32_t(centre)));
        CHECK(norm(L.ibp_rest[m] - L.ibp_rest[centre]) < 2.9f * 0.02f);  // two edges, diagonals √2 r0
    }
}

TEST_CASE("A cloth hung by two edges settles, and its sag shrinks with the step toward an inextensible sheet's") {
    // Shape matching pulls each node α of the way to its goal every step, so the cloth's stiffness
    // grows as the step shrinks: its stretch under its own weight is about proportional to the
    // step (docs/cloth.md).
    std::map<double, double> sags;
    for (double dt : {0.002, 0.001, 0.0005}) {
        const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup_of(hammock(dt)), 1);
        while (sim->time() < 2.0 - 1e-9) sim->step();
        HostParticles p;
        sim->download(p);
        INFO("dt " << dt);
        CHECK(fastest(p, kInnerBoundary) < 0.02);  // at rest after a few swings
        sags[dt] = sag(p, 0.4);
        MESSAGE("hammock at dt " << dt << " s: sag " << sags[dt] * 1000 << " mm");
    }
    CHECK(sags[0.002] > sags[0.001]);
    CHECK(sags[0.001] > sags[0.0005]);
    CHECK(sags[0.0005] > 0);
    CHECK(sags[0.0005] < 0.35 * sags[0.002]);
    // About proportional: sag / dt within 25% from one step to the next.
    for (double dt : {0.001, 0.0005}) {
        const double ratio = (sags[dt] / dt) / (sags[2 * dt] / (2 * dt));
        CHECK(ratio > 0.75);
        CHECK(ratio < 1.25);
    }
}

TEST_CASE("Water on a cloth stays on it, met from above or from below, and weighs it down") {
    const double substep = 0.0005;
    const std::unique_ptr<Simulation> alone = create_openmp_simulation(setup_of(basin(1500, false, substep, false)), 2);
    while (alone->time() < 0.5 - 1e-9) alone->step();
    HostParticles dry;
    alone->download(dry);
    const double dry_sag = sag(dry, 0.3);
    std::map<bool, double> wet_sag;
    for (bool from_below : {false, true}) {
        INFO((from_below ? "water under the cloth, gravity reversed" : "water on the cloth"));
        const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup_of(basin(1500, from_below, substep)), 2);
        CrossingCount count;
        count.upward = from_below;
        const HostParticles p = run_counting(*sim, 0.5, count);
        CHECK(count.crossings == 0);
        wet_sag[from_below] = sag(p, 0.3, from_below);
        CHECK(fastest(p, kFluid) < 3.5);  // the spill over the rim falls 0.3 m: 2.4 m/s
        MESSAGE((from_below ? "from below" : "from above") << ": sag " << wet_sag[from_below] * 1000 << " mm, dry "
                                                          << dry_sag * 1000 << " mm");
    }
    CHECK(wet_sag[false] > 2 * dry_sag);
    // The mirrored scene bends the cloth the other way by as much.
    CHECK(wet_sag[true] == doctest::Approx(wet_sag[false]).epsilon(0.15));
}

TEST_CASE("A cloth lighter than the water on it holds only while its nodes answer inside PCISPH") {
    // 300 kg/m3 (the paper's Fig. 10) under 4 layers of water, stiff (0.25 ms substeps): answered
    // after the solve, the nodes overshoot and the run blows up within a few steps
    // (coupling.strong off); answered inside it, it runs, and no water passes through.
    const double substep = 0.00025;
    {
        const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup_of(basin(300, false, substep)), 2);
        CrossingCount count;
        const HostParticles p = run_counting(*sim, 0.3, count);
        CHECK(count.crossings == 0);
        CHECK(fastest(p, kInnerBoundary) < 5);
    }
    // Without the answer: within 0.1 s (or 300 steps, as its steps shrink) a node passes the
    // 5 m/s the answered run stays under, many times over (12 m/s at 0.1 s), or a value is no
    // longer finite (the program's speed guard stops such a run).
    const std::unique_ptr<Simulation> weak =
        create_openmp_simulation(setup_of(basin(300, false, substep), {"coupling.strong=false"}), 2);
    for (int step = 0; step < 300 && weak->time() < 0.1; ++step) weak->step();
    HostParticles p;
    weak->download(p);
    const double top = fastest(p, kInnerBoundary);
    MESSAGE("without coupling.strong: the cloth's top speed " << top << " m/s at t = " << weak->time() << " s");
    CHECK(!(top < 5));
}

TEST_CASE("A cloth must be an open, manifold sheet, and its pins must hold some of it") {
    const auto error_of = [](const std::string& mesh, const std::string& pinned) {
        try {
            setup_of(R"({ "domain": { "min": [0, 0, 0], "max": [0.5, 0.5, 0.5] }, "fluid": { "spacing": 0.02 },
  "objects": [ { "name": "c", "mesh": { "procedural": ")" + mesh + R"(" }, "transform": { "translation": [0.25, 0.25, 0.25] },
    "kind": "cloth")" + pinned + R"( } ] })");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error_of("box:x=0.1,y=0.1,z=0.1", "").find("the mesh is closed, and a cloth is an open sheet") != std::string::npos);
    const std::string outside = error_of(
        "sheet:x=0.2,z=0.2,nx=10,nz=10", R"(, "pinned": { "boxes": [ { "min": [0.0, 0.0, 0.0], "max": [0.05, 0.05, 0.05] } ] })");
    CHECK(outside.find("pinned box 0") != std::string::npos);
    CHECK(outside.find("holds none of the object's inner particles (the cloth's vertices)") != std::string::npos);
    CHECK(error_of("sheet:x=0.2,z=0.2,nx=10,nz=10", "") == "no error");
}

TEST_CASE("A cloth under water resumes bitwise from a checkpoint") {
    // The nodes' answer carries each node's last velocity and the last step's size into the next
    // step: the checkpoint must too.
    const test::SplitRun run = test::run_split(setup_of(basin(300, false, 0.00025)), 40, 30);
    REQUIRE(run.uninterrupted.position.size() == run.resumed.position.size());
    CHECK(std::memcmp(run.uninterrupted.position.data(), run.resumed.position.data(),
                      run.resumed.position.size() * sizeof(Vec3)) == 0);
    CHECK(std::memcmp(run.uninterrupted.velocity.data(), run.resumed.velocity.data(),
                      run.resumed.velocity.size() * sizeof(Vec3)) == 0);
}

TEST_CASE("CUDA: a cloth under water moves as on OpenMP") {
    if (!cuda_backend_info().available) {
        MW_SKIP("no CUDA device: the cross-backend cloth test needs one");
        return;
    }
    // 40 steps (about 40 ms): the water has settled onto the cloth, nothing has spilled yet.
    const test::OpenmpAndCuda both = test::run_openmp_and_cuda(setup_of(basin(1500, false, 0.0005)), 40);
    const double nodes = test::largest_position_difference(both.openmp, both.cuda, [](std::uint8_t t) { return t == kInnerBoundary; });
    MESSAGE("cloth nodes differ by at most " << nodes << " m");
    CHECK(nodes < 1e-4);
}
