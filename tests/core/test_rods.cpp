// Rods (docs/rods.md): one line of nodes, shape-matched over runs of 2w + 1 nodes along it, met
// by the fluid from every side; a cantilever's sag against the law of shape matching at rest; a
// rod under a stream falling at 4 m/s (scenes/rod_stream.json) with and without the correction;
// bad rods refused.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "algorithms/lsm_regions.hpp"
#include "apps/scene.hpp"
#include "common/errors.hpp"
#include "simulation/factory.hpp"
#include "test_setups.hpp"
#include "../scratch_dir.hpp"
#include "../skip.hpp"

using namespace mw;

namespace {

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", v);
    return text;
}

// A level rod 0.4 m long (21 nodes) at y = 0.4, clamped at its left end (three nodes pinned),
// alone, at fixed steps `dt`.
std::string cantilever(double dt, double alpha) {
    return R"({
  "domain": { "min": [0, 0, 0], "max": [0.6, 0.6, 0.3] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": )" + number(dt) + R"(, "dt_mode": "fixed" },
  "boundary": { "walls": false },
  "objects": [ { "name": "rod", "mesh": { "procedural": "line:length=0.4" },
    "transform": { "translation": [0.3, 0.4, 0.15] }, "kind": "rod", "density": 1000,
    "lsm": { "w": 3, "alpha": )" + number(alpha) + R"(, "damping": 5, "body_damping": 5 },
    "pinned": { "box": { "min": [0.09, 0.39, 0.14], "max": [0.141, 0.41, 0.16] } } } ]
})";
}

SimulationSetup setup_of(const std::string& json, const std::vector<std::string>& overrides = {}) {
    return build_setup(parse_scene_text(json, "rod test", overrides));
}

// The rod's nodes, first to last (the host order is the scene's).
std::vector<Vec3> nodes_of(const HostParticles& p) {
    std::vector<Vec3> nodes;
    for (std::size_t i = 0; i < p.type.size(); ++i)
        if (p.type[i] == kInnerBoundary) nodes.push_back(p.position[i]);
    return nodes;
}

// The mean drop of the nodes below y0.
double mean_sag(const HostParticles& p, double y0) {
    const std::vector<Vec3> nodes = nodes_of(p);
    double sum = 0;
    for (const Vec3& x : nodes) sum += y0 - double(x.y);
    return sum / double(nodes.size());
}

double distance_to_segment(Vec3 x, Vec3 a, Vec3 b) {
    const Vec3 ab = b - a;
    const double t = std::clamp(double(dot(x - a, ab)) / double(dot(ab, ab)), 0.0, 1.0);
    return double(norm(x - (a + Real(t) * ab)));
}

// The closest any fluid particle comes to the rod's centreline (the polyline through its nodes).
double closest_fluid(const HostParticles& p) {
    const std::vector<Vec3> nodes = nodes_of(p);
    double closest = 1e30;
    for (std::size_t i = 0; i < p.type.size(); ++i) {
        if (p.type[i] != kFluid) continue;
        for (std::size_t k = 0; k + 1 < nodes.size(); ++k)
            closest = std::min(closest, distance_to_segment(p.position[i], nodes[k], nodes[k + 1]));
    }
    return closest;
}

struct StreamRun {
    double closest = 1e30;  // m, over every step
    double lowest_tip = 1e30;
    double fastest_fluid = 0;
};

// scenes/rod_stream.json to `until`, watching every step.
StreamRun run_stream(double until, const std::vector<std::string>& overrides) {
    const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/rod_stream.json", overrides);
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(build_setup(scene), 2);
    StreamRun r;
    HostParticles p;
    while (sim->time() < until - 1e-9) {
        sim->step();
        sim->download(p);
        r.closest = std::min(r.closest, closest_fluid(p));
        const double tip = double(nodes_of(p).back().y);
        r.lowest_tip = std::min(r.lowest_tip, tip);
        for (std::size_t i = 0; i < p.type.size(); ++i)
            if (p.type[i] == kFluid) r.fastest_fluid = std::max(r.fastest_fluid, double(norm(p.velocity[i])));
    }
    return r;
}

}  // namespace

TEST_CASE("A rod's nodes lie r0 apart along its line, each weighing its share of it, and its regions are runs of 2w + 1") {
    const SimulationSetup setup = setup_of(R"({
  "domain": { "min": [0, 0, 0], "max": [0.5, 0.5, 0.5] },
  "fluid": { "spacing": 0.02 },
  "objects": [ { "name": "rod", "mesh": { "procedural": "line:length=0.3" },
    "transform": { "rotation_deg": [0, 0, 30], "translation": [0.25, 0.25, 0.25] }, "kind": "rod", "density": 2000,
    "lsm": { "w": 3 } } ]
})");
    REQUIRE(setup.solids.size() == 1);
    const SolidSetup& rod = setup.solids[0];
    CHECK(rod.ibp.size() == 16);  // 0.3 m at r0 = 0.02: 15 segments
    CHECK(rod.gp.size() == 16);
    CHECK(rod.sbp.size() == 30);  // two per segment
    CHECK(rod.triangles.empty());
    double mass = 0;
    for (Real m : rod.ibp_mass) mass += m;
    CHECK(mass == doctest::Approx(2000 * 0.02 * 0.02 * 0.3).epsilon(1e-5));  // density x r0^2 x length
    for (std::size_t k = 0; k + 1 < rod.ibp.size(); ++k)
        CHECK(double(norm(setup.position[rod.ibp[k + 1]] - setup.position[rod.ibp[k]])) == doctest::Approx(0.02).epsilon(1e-4));
    const LsmHostLayout L = build_lsm_layout(setup);
    REQUIRE(L.sbp_sides.size() == L.sbp_count);
    CHECK(std::all_of(L.sbp_sides.begin(), L.sbp_sides.end(), [](std::uint8_t t) { return t == kSbpAround; }));
    CHECK(std::all_of(L.sbp.begin(), L.sbp.end(), [](const SbpLink& s) { return s.is_segment(); }));
    // The SBPs store their segment's tangent: the line's direction, 30 degrees from x.
    const Vec3 along{Real(std::cos(M_PI / 6)), Real(std::sin(M_PI / 6)), 0};
    for (const Vec3& t : L.sbp_normal) CHECK(double(dot(t, along)) == doctest::Approx(1).epsilon(1e-5));
    const auto members = [&](std::size_t r) { return L.region_end[r] - L.region_offsets[r]; };
    CHECK(members(0) == 4);   // an end: itself and 3 along
    CHECK(members(8) == 7);   // inside: 3 either way
    CHECK(members(15) == 4);
    CHECK(L.objects[0].nodal == 1);  // its nodes answer inside PCISPH, as a cloth's do
}

TEST_CASE("A clamped rod's sag at rest follows shape matching's law: g dt^2 / alpha times a constant of its shape") {
    // At rest each node sits where the shape matching's pull, α (goal - x) per step, cancels
    // gravity's g dt² per step: g dt² / α from its goal. Small, the sag is linear in those
    // offsets: proportional to dt² / α (docs/rods.md).
    std::map<std::pair<double, double>, double> sags;
    for (const auto& step_and_alpha : std::vector<std::pair<double, double>>{{0.001, 0.5}, {0.0005, 0.5}, {0.00025, 0.5}, {0.0005, 1.0}}) {
        // Named copies: INFO's lambda cannot capture a structured binding under clang 14.
        const double dt = step_and_alpha.first, alpha = step_and_alpha.second;
        const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup_of(cantilever(dt, alpha)), 1);
        while (sim->time() < 2.0 - 1e-9) sim->step();
        HostParticles p;
        sim->download(p);
        double fastest = 0;
        for (std::size_t i = 0; i < p.type.size(); ++i)
            if (p.type[i] == kInnerBoundary) fastest = std::max(fastest, double(norm(p.velocity[i])));
        INFO("dt " << dt << " alpha " << alpha);
        CHECK(fastest < 0.01);  // at rest
        sags[{dt, alpha}] = mean_sag(p, 0.4);
        MESSAGE("cantilever at dt " << dt << " s, alpha " << alpha << ": mean sag " << sags[{dt, alpha}] * 1000 << " mm");
    }
    const auto constant = [&](double dt, double alpha) { return sags[{dt, alpha}] * alpha / (dt * dt); };
    const double reference = constant(0.00025, 0.5);
    CHECK(reference > 0);
    CHECK(constant(0.0005, 0.5) == doctest::Approx(reference).epsilon(0.05));
    CHECK(constant(0.0005, 1.0) == doctest::Approx(reference).epsilon(0.05));
    // At 1 ms the sag (53 mm, an eighth of the rod) is past the small-sag range: less than the law.
    CHECK(constant(0.001, 0.5) < reference);
    CHECK(constant(0.001, 0.5) > 0.75 * reference);
}

TEST_CASE("Water falling on a rod at 4 m/s parts round it, and bends it down") {
    // scenes/rod_stream.json at its largest steps (CFL 1, up to 30 ms) over the stream's first
    // second: the correction keeps the water its band (0.45 r0) from the line, less what the
    // line's bending adds within a step; without it the water reaches within 0.02 r0 (EPYC VM).
    const std::vector<std::string> largest = {"solver.cfl_number=1", "solver.dt=0.03"};
    const StreamRun with = run_stream(1.0, largest);
    MESSAGE("rod under the stream: closest water " << with.closest / 0.02 << " r0, tip down to " << with.lowest_tip
                                                   << " m, fastest water " << with.fastest_fluid << " m/s");
    CHECK(with.closest > 0.3 * 0.02);
    CHECK(with.lowest_tip < 0.4 - 0.02);  // bent by more than r0 under the stream
    CHECK(with.fastest_fluid > 3.5);      // the stream arrives at about 4 m/s
    // The swinging rod throws some of it off its tip at twice that (docs/rods.md, "Limits").
    CHECK(with.fastest_fluid < 20);
    std::vector<std::string> without = largest;
    without.push_back("coupling.correction=false");
    const StreamRun bare = run_stream(1.0, without);
    MESSAGE("without the correction: closest water " << bare.closest / 0.02 << " r0");
    CHECK(bare.closest < 0.3 * 0.02);
}

TEST_CASE("A rod's centreline can be an OBJ polyline: a hook, resampled along its bend") {
    // An L of 0.2 m down and 0.1 m across, as an OBJ line, scaled by the scene's transform.
    const std::filesystem::path obj = mw_test::scratch_dir("meltwater_core_test") / "hook.obj";
    {
        std::ofstream out(obj);
        out << "v 0 0.1 0\nv 0 -0.1 0\nv 0.1 -0.1 0\nl 1 2 3\n";
    }
    const SimulationSetup setup = setup_of(R"({
  "domain": { "min": [0, 0, 0], "max": [0.5, 0.5, 0.5] },
  "fluid": { "spacing": 0.02 },
  "objects": [ { "name": "hook", "mesh": { "file": ")" + obj.string() + R"(" },
    "transform": { "scale": [1, 1, 1], "translation": [0.2, 0.25, 0.25] }, "kind": "rod", "density": 2000 } ]
})");
    REQUIRE(setup.solids.size() == 1);
    const SolidSetup& rod = setup.solids[0];
    CHECK(rod.ibp.size() == 16);  // 0.3 m in 15 steps of 0.02 m
    const Vec3 first = setup.position[rod.ibp.front()], last = setup.position[rod.ibp.back()];
    CHECK(double(norm(first - Vec3{0.2f, 0.35f, 0.25f})) < 1e-6);
    CHECK(double(norm(last - Vec3{0.3f, 0.15f, 0.25f})) < 1e-6);
    double mass = 0;
    for (Real m : rod.ibp_mass) mass += m;
    CHECK(mass == doctest::Approx(2000 * 0.02 * 0.02 * 0.3).epsilon(1e-5));
    // The same file as an elastic object: a line is a rod's.
    std::string elastic;
    try {
        setup_of(R"({ "domain": { "min": [0, 0, 0], "max": [0.5, 0.5, 0.5] }, "fluid": { "spacing": 0.02 },
  "objects": [ { "name": "hook", "mesh": { "file": ")" + obj.string() + R"(" },
    "transform": { "translation": [0.2, 0.25, 0.25] }, "kind": "elastic" } ] })");
    } catch (const InputError& e) {
        elastic = e.what();
    }
    CHECK(elastic.find("give the object kind \"rod\"") != std::string::npos);
}

TEST_CASE("A rod needs a line of three nodes or more, and a line is only a rod's") {
    const auto error_of = [](const std::string& mesh, const std::string& kind) {
        try {
            setup_of(R"({ "domain": { "min": [0, 0, 0], "max": [0.5, 0.5, 0.5] }, "fluid": { "spacing": 0.02 },
  "objects": [ { "name": "r", "mesh": { "procedural": ")" + mesh + R"(" }, "transform": { "translation": [0.25, 0.25, 0.25] },
    "kind": ")" + kind + R"(" } ] })");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error_of("line:length=0.02", "rod").find("a rod needs at least 3") != std::string::npos);
    CHECK(error_of("box:x=0.1,y=0.1,z=0.1", "rod").find("a rod is a line") != std::string::npos);
    CHECK(error_of("line:length=0.2", "elastic").find("give the object kind \"rod\"") != std::string::npos);
    CHECK(error_of("line:length=0.021", "rod") == "no error");
}

TEST_CASE("CUDA: a rod under a stream moves as on OpenMP") {
    if (!cuda_backend_info().available) {
        MW_SKIP("no CUDA device: the cross-backend rod test needs one");
        return;
    }
    const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/rod_stream.json", {"solver.dt_mode=fixed", "solver.dt=0.001"});
    // 150 steps: the stream has reached the rod.
    const test::OpenmpAndCuda both = test::run_openmp_and_cuda(build_setup(scene), 150);
    const double nodes = test::largest_position_difference(both.openmp, both.cuda, [](std::uint8_t t) { return t == kInnerBoundary; });
    MESSAGE("rod nodes differ by at most " << nodes << " m");
    CHECK(nodes < 1e-3);
}
