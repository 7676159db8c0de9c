// Solids meeting solids (docs/contact.md): moving objects resting on static boxes and on a static
// stair mesh, a stack of two boxes, a fast drop onto a thin static box, a cloth draped over a box
// with a ball on it, and the momentum two objects exchange in an impact (algorithms/solid_obstacles.hpp, solid_collisions.hpp).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "algorithms/lsm_regions.hpp"
#include "apps/scene.hpp"
#include "apps/scene_builder.hpp"
#include "simulation/factory.hpp"
#include "test_setups.hpp"

using namespace mw;

namespace {

constexpr double kR0 = 0.02;

SimulationSetup setup_of(const std::string& json, const std::vector<std::string>& overrides = {}) {
    return build_setup(parse_scene_text(json, "collision test", overrides));
}

// Each object's IBP centroid (by the object number the particles carry).
std::vector<Vec3> centroids(const HostParticles& p, std::size_t objects) {
    std::vector<Vec3> sum(objects, Vec3{0, 0, 0});
    std::vector<double> count(objects, 0);
    for (std::size_t i = 0; i < p.type.size(); ++i) {
        if (p.type[i] != kInnerBoundary || p.object[i] < 0 || std::size_t(p.object[i]) >= objects) continue;
        sum[std::size_t(p.object[i])] += p.position[i];
        count[std::size_t(p.object[i])] += 1;
    }
    for (std::size_t o = 0; o < objects; ++o)
        if (count[o] > 0) sum[o] = (Real(1) / Real(count[o])) * sum[o];
    return sum;
}

void run_to(Simulation& sim, double t) {
    while (sim.time() < t - 1e-9) sim.step();
}

// The scene's moving solids' momentum: Σ m v over their IBPs (masses from the LSM layout; the
// host arrays are in the scene's order).
struct MomentumMeter {
    std::vector<std::uint32_t> scene_index;
    std::vector<Real> mass;
    explicit MomentumMeter(const SimulationSetup& setup) {
        const LsmHostLayout L = build_lsm_layout(setup);
        scene_index.assign(L.scene_index.begin(), L.scene_index.begin() + std::ptrdiff_t(L.ibp_count));
        mass = L.ibp_mass;
    }
    Vec3 operator()(const HostParticles& p) const {
        double m[3] = {0, 0, 0};
        for (std::size_t s = 0; s < mass.size(); ++s) {
            const Vec3 v = p.velocity[scene_index[s]];
            m[0] += double(mass[s]) * double(v.x), m[1] += double(mass[s]) * double(v.y), m[2] += double(mass[s]) * double(v.z);
        }
        return Vec3{Real(m[0]), Real(m[1]), Real(m[2])};
    }
    // Σ m |v|: the scale the momentum's error is measured against.
    double scale(const HostParticles& p) const {
        double sum = 0;
        for (std::size_t s = 0; s < mass.size(); ++s) sum += double(mass[s]) * double(norm(p.velocity[scene_index[s]]));
        return sum;
    }
};

// The mean velocity of object o's IBPs.
Vec3 mean_velocity(const HostParticles& p, int o) {
    Vec3 sum{0, 0, 0};
    double count = 0;
    for (std::size_t i = 0; i < p.type.size(); ++i)
        if (p.type[i] == kInnerBoundary && p.object[i] == o) sum += p.velocity[i], count += 1;
    return (Real(1) / Real(count)) * sum;
}

// The closest two IBPs of objects a and b come.
double closest_approach(const HostParticles& p, int a, int b) {
    double best = 1e30;
    for (std::size_t i = 0; i < p.type.size(); ++i) {
        if (p.type[i] != kInnerBoundary || p.object[i] != a) continue;
        for (std::size_t j = 0; j < p.type.size(); ++j)
            if (p.type[j] == kInnerBoundary && p.object[j] == b) best = std::min(best, double(norm(p.position[i] - p.position[j])));
    }
    return best;
}

// A static box 0.2 m high (its top at y = 0.2), a box object of `kind` dropped onto it from 5 cm,
// and a second one dropped onto that (`stacked`).
std::string on_a_box(const std::string& lower, const std::string& upper, bool stacked) {
    std::string objects = R"({ "name": "lower", "mesh": { "procedural": "box:x=0.1,y=0.1,z=0.1" },
      "transform": { "translation": [0.12, 0.3, 0.2] }, "kind": ")" + lower + R"(", "density": 500,
      "lsm": { "alpha": 0.5, "damping": 2 } })";
    if (stacked)
        objects += R"(, { "name": "upper", "mesh": { "procedural": "box:x=0.1,y=0.1,z=0.1" },
      "transform": { "translation": [0.12, 0.42, 0.2] }, "kind": ")" + upper + R"(", "density": 500,
      "lsm": { "alpha": 0.5, "damping": 2 } })";
    return R"({
  "domain": { "min": [0, 0, 0], "max": [0.6, 0.6, 0.4] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.002 },
  "static_boxes": [ { "min": [0.0, 0.0, 0.0], "max": [0.3, 0.2, 0.4] } ],
  "objects": [ )" + objects + R"( ]
})";
}

}  // namespace

TEST_CASE("A box dropped onto a static box rests on it, and a second box rests on the first") {
    struct Case {
        std::string lower, upper;
        bool stacked;
    };
    for (const Case& c : {Case{"rigid", "", false}, Case{"elastic", "", false}, Case{"rigid", "rigid", true},
                         Case{"rigid", "elastic", true}, Case{"elastic", "rigid", true}}) {
        INFO(c.lower << (c.stacked ? std::string(" under ") + c.upper : std::string(" alone")));
        const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup_of(on_a_box(c.lower, c.upper, c.stacked)), 1);
        run_to(*sim, 1.0);
        HostParticles p;
        sim->download(p);
        const std::vector<Vec3> settled = centroids(p, c.stacked ? 2 : 1);
        run_to(*sim, 3.0);
        sim->download(p);
        const std::vector<Vec3> later = centroids(p, c.stacked ? 2 : 1);
        // On the box's top (0.2) and on each other: centres 0.05 and 0.15 m above it, the
        // elastic ones a little lower for their sag under their own and the upper box's weight.
        CHECK(settled[0].y == doctest::Approx(0.25).epsilon(0.2 * kR0 / 0.25));
        if (c.stacked) CHECK(settled[1].y == doctest::Approx(0.35).epsilon(0.3 * kR0 / 0.35));
        for (std::size_t o = 0; o < settled.size(); ++o) {
            const double drift = norm(later[o] - settled[o]);
            MESSAGE(c.lower << (c.stacked ? std::string(" under ") + c.upper : std::string(" alone")) << ", object " << o
                            << ": at y " << later[o].y << ", drift over 2 s " << drift / kR0 << " r0");
            CHECK(drift < 0.1 * kR0);
        }
    }
}

TEST_CASE("With solver.solid_contact off, a box dropped onto another passes into it, and still rests on the static box") {
    const std::unique_ptr<Simulation> sim =
        create_openmp_simulation(setup_of(on_a_box("rigid", "rigid", true), {"solver.solid_contact=false"}), 1);
    run_to(*sim, 1.0);
    HostParticles p;
    sim->download(p);
    const std::vector<Vec3> at = centroids(p, 2);
    MESSAGE("contact off: lower box at y " << at[0].y << ", upper at " << at[1].y);
    CHECK(at[0].y == doctest::Approx(0.25).epsilon(0.2 * kR0 / 0.25));
    CHECK(at[1].y == doctest::Approx(0.25).epsilon(0.2 * kR0 / 0.25));  // inside the lower one, on the static box
}

TEST_CASE("Boxes dropped onto a static stair mesh rest on its steps") {
    // The stair's steps: 0.2 m deep, 0.1 m high, starting at z = 0.1; step k's tread at
    // y = 0.1 (k + 1) for z in 0.1 + 0.2 [k, k + 1].
    const std::string scene = R"({
  "domain": { "min": [0, 0, 0], "max": [0.8, 0.6, 1.0] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.002 },
  "objects": [
    { "name": "stair", "mesh": { "procedural": "stairs:steps=4,width=0.6,depth=0.2,height=0.1" },
      "transform": { "translation": [0.4, 0.2, 0.5] }, "kind": "static" },
    { "name": "heavy", "mesh": { "procedural": "box:x=0.12,y=0.08,z=0.12" },
      "transform": { "translation": [0.25, 0.32, 0.4] }, "kind": "rigid", "density": 8000 },
    { "name": "light", "mesh": { "procedural": "box:x=0.12,y=0.08,z=0.12" },
      "transform": { "translation": [0.55, 0.42, 0.6] }, "kind": "elastic", "density": 200,
      "lsm": { "alpha": 0.5, "damping": 2 } } ]
})";
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup_of(scene), 1);
    run_to(*sim, 1.0);
    HostParticles p;
    sim->download(p);
    const std::vector<Vec3> settled = centroids(p, 3);
    run_to(*sim, 3.0);
    sim->download(p);
    const std::vector<Vec3> later = centroids(p, 3);
    CHECK(settled[1].y == doctest::Approx(0.24).epsilon(0.2 * kR0 / 0.24));  // step 1: tread 0.2, half-height 0.04
    CHECK(settled[2].y == doctest::Approx(0.34).epsilon(0.3 * kR0 / 0.34));  // step 2: tread 0.3
    for (std::size_t o : {std::size_t(1), std::size_t(2)}) {
        MESSAGE("stair, object " << o << ": at y " << later[o].y << ", drift over 2 s " << norm(later[o] - settled[o]) / kR0 << " r0");
        CHECK(norm(later[o] - settled[o]) < 0.1 * kR0);
    }
}

TEST_CASE("A box dropped fast onto a thin static box stops on it") {
    // 4 m/s onto a plate one r0 thick: 8 mm a step at 2 ms.
    const std::string scene = R"({
  "domain": { "min": [0, 0, 0], "max": [0.4, 0.6, 0.4] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.002 },
  "static_boxes": [ { "min": [0.0, 0.2, 0.0], "max": [0.4, 0.22, 0.4] } ],
  "objects": [ { "name": "box", "mesh": { "procedural": "box:x=0.1,y=0.1,z=0.1" },
      "transform": { "translation": [0.2, 0.4, 0.2] }, "velocity": [0, -4, 0], "kind": "rigid", "density": 500 } ]
})";
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup_of(scene), 1);
    run_to(*sim, 0.5);
    HostParticles p;
    sim->download(p);
    CHECK(centroids(p, 1)[0].y == doctest::Approx(0.27).epsilon(0.2 * kR0 / 0.27));
}

TEST_CASE("A cloth dropped onto a static box drapes over it, and a ball dropped onto the cloth rests on it") {
    const std::string scene = R"({
  "domain": { "min": [0, 0, 0], "max": [0.6, 0.6, 0.6] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.001, "dt_mode": "fixed" },
  "static_boxes": [ { "min": [0.2, 0.0, 0.2], "max": [0.4, 0.25, 0.4] } ],
  "objects": [ { "name": "cloth", "mesh": { "procedural": "sheet:x=0.4,z=0.4,nx=20,nz=20" },
    "transform": { "translation": [0.3, 0.35, 0.3] }, "kind": "cloth", "density": 300,
    "lsm": { "alpha": 0.5, "damping": 5, "body_damping": 5 } },
    { "name": "ball", "mesh": { "procedural": "sphere:radius=0.05" }, "transform": { "translation": [0.3, 0.5, 0.3] },
      "kind": "rigid", "density": 2000 } ]
})";
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup_of(scene), 1);
    run_to(*sim, 1.5);
    HostParticles p;
    sim->download(p);
    // No cloth node inside the box grown by most of its margin (r0/2), none far below its top
    // over the box, and the ball on the cloth on the box: its centre a radius, a node's margin
    // and the ball's above the top, to within r0/2.
    double deepest = 0, lowest_over_top = 1;
    for (std::size_t i = 0; i < p.type.size(); ++i) {
        if (p.type[i] != kInnerBoundary || p.object[i] != 0) continue;
        const Vec3 x = p.position[i];
        const double inside_x = std::min(double(x.x) - 0.2, 0.4 - double(x.x));
        const double inside_z = std::min(double(x.z) - 0.2, 0.4 - double(x.z));
        const double inside = std::min({inside_x, inside_z, 0.25 - double(x.y)}) + 0.5 * kR0;
        deepest = std::max(deepest, inside);
        if (inside_x > 0.02 && inside_z > 0.02) lowest_over_top = std::min(lowest_over_top, double(x.y));
    }
    const double ball_y = centroids(p, 2)[1].y;
    MESSAGE("drape: deepest node " << deepest / kR0 << " r0 into the box's margin; lowest node over the top at y "
                                   << lowest_over_top << "; ball at y " << ball_y);
    CHECK(deepest < 0.1 * kR0);
    CHECK(lowest_over_top > 0.25);
    CHECK(ball_y == doctest::Approx(0.25 + 0.5 * kR0 + 0.05).epsilon(0.5 * kR0 / 0.31));
}

TEST_CASE("Two solids that collide exchange momentum and keep its total") {
    // No gravity, no walls reached: two objects meet off-centre (so they also spin) at 3 m/s
    // relative. Σ m v over their IBPs before and after must agree to 1e-5 of its scale.
    for (const char* kinds : {"rigid rigid", "elastic elastic", "rigid elastic"}) {
        const std::string a = std::string(kinds).substr(0, std::string(kinds).find(' '));
        const std::string b = std::string(kinds).substr(std::string(kinds).find(' ') + 1);
        const std::string scene = R"({
  "domain": { "min": [0, 0, 0], "max": [1.2, 0.6, 0.6] },
  "gravity": [0, 0, 0],
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.001 },
  "boundary": { "walls": false },
  "objects": [
    { "name": "a", "mesh": { "procedural": "box:x=0.1,y=0.1,z=0.1" }, "transform": { "translation": [0.4, 0.3, 0.3] },
      "velocity": [2, 0, 0], "kind": ")" + a + R"(", "density": 500, "lsm": { "alpha": 0.5 } },
    { "name": "b", "mesh": { "procedural": "box:x=0.1,y=0.1,z=0.1" }, "transform": { "translation": [0.6, 0.34, 0.31] },
      "velocity": [-1, 0, 0], "kind": ")" + b + R"(", "density": 1500, "lsm": { "alpha": 0.5 } } ]
})";
        INFO(std::string(kinds));
        const SimulationSetup setup = setup_of(scene);
        const MomentumMeter momentum(setup);
        const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 1);
        HostParticles p;
        sim->download(p);
        const Vec3 before = momentum(p);
        const double scale = momentum.scale(p);
        double closest = 1e30;
        for (int k = 0; k < 60; ++k) {  // 60 ms: the gap of 0.1 m closes at 3 m/s after about 27 ms
            sim->step();
            sim->download(p);
            closest = std::min(closest, closest_approach(p, 0, 1));
        }
        const Vec3 after = momentum(p);
        MESSAGE(std::string(kinds) << ": momentum before (" << before.x << ", " << before.y << ", " << before.z << "), after ("
                      << after.x << ", " << after.y << ", " << after.z << "); closest IBPs " << closest / kR0 << " r0");
        CHECK(norm(after - before) < 1e-5 * scale);
        // They met (a, three times lighter, was turned back: the pair's common velocity is
        // -0.25 m/s) and did not pass into each other.
        CHECK(mean_velocity(p, 0).x < 0.5);
        CHECK(closest > 0.7 * kR0);
    }
}
