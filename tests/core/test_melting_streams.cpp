// The paper's Fig. 11b (scenes/melting_streams.json): four cubes at -5 C under streams of water at
// 60 C, with the paper's conductivities (K 70, 50, 30, 10, as diffusivities in that ratio) and
// densities (200, 10,000, 8,000 and 300 kg/m³), each with ice's heat per kilogram, so that the heat
// a cubic metre needs to melt follows its density. What must hold: the best conductor, light,
// melts first and wholly; the light poor conductor melts behind it; the heavy cubes, needing 27 to
// 33 times the heat a cubic metre, melt least and stay on the floor; every melted particle joins
// the water; nothing is lost, and nothing runs faster than the streams' fall.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "apps/scene.hpp"
#include "apps/scene_builder.hpp"
#include "simulation/factory.hpp"

using namespace mw;

namespace {

constexpr int kCubes = 4;  // green (K 70, 200 kg/m3), red (K 50, 10,000), yellow (K 30, 8,000), blue (K 10, 300)
constexpr long kParticlesPerCube = 125;  // a 5 x 5 x 5 lattice at r0 0.02 m

struct Census {
    std::array<long, kCubes> left{};        // each cube's particles not melted
    std::array<double, kCubes> centre_y{};  // their mean height, m
    long fluid = 0;
    long inside = 0;     // fluid particles within r0/2 of a cube's lattice vertex: in its cell
    double fastest = 0;  // m/s, any particle
};

Census census(const HostParticles& p) {
    Census c;
    std::vector<Vec3> lattice;
    for (std::size_t i = 0; i < p.type.size(); ++i)
        if (p.type[i] != kFluid && p.object[i] >= 0 && p.object[i] < kCubes) lattice.push_back(p.position[i]);
    const Real half_r0 = Real(0.01);
    for (std::size_t i = 0; i < p.type.size(); ++i)
        if (p.type[i] == kFluid)
            c.inside += std::any_of(lattice.begin(), lattice.end(),
                                    [&](const Vec3& b) { return norm2(b - p.position[i]) < half_r0 * half_r0; });
    for (std::size_t i = 0; i < p.type.size(); ++i) {
        c.fastest = std::max(c.fastest, double(norm(p.velocity[i])));
        if (p.type[i] == kFluid) ++c.fluid;
        const std::int32_t o = p.object[i];
        if ((p.type[i] == kSurfaceBoundary || p.type[i] == kInnerBoundary) && o >= 0 && o < kCubes) {
            ++c.left[std::size_t(o)];
            c.centre_y[std::size_t(o)] += double(p.position[i].y);
        }
    }
    for (int k = 0; k < kCubes; ++k)
        if (c.left[std::size_t(k)] > 0) c.centre_y[std::size_t(k)] /= double(c.left[std::size_t(k)]);
    return c;
}

}  // namespace

TEST_CASE("Four cubes under warm streams (Fig. 11b) melt in the order their conductivity and density set") {
    const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/melting_streams.json");
    // One thread: many small kernels a step, as the thin box's test says (test_thin_box.cpp).
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(build_setup(scene), 1);
    HostParticles p;
    sim->download(p);
    const Census start = census(p);
    for (int k = 0; k < kCubes; ++k) CHECK(start.left[std::size_t(k)] == kParticlesPerCube);
    // To the streams' end (2 s), looking every 0.25 s.
    Census now = start;
    double fastest = 0;
    long most_inside = 0;
    bool green_ahead = true;  // the green cube has melted at least as much as the blue one at every look
    for (double look = 0.25; look <= 2.0 + 1e-9; look += 0.25) {
        while (sim->time() < look - 1e-9) {
            sim->step();
            CHECK_FALSE(sim->last_report().diverged);
        }
        sim->download(p);
        now = census(p);
        fastest = std::max(fastest, now.fastest);
        most_inside = std::max(most_inside, now.inside);
        green_ahead = green_ahead && now.left[0] <= now.left[3];
        MESSAGE("t " << sim->time() << " s: left " << now.left[0] << ", " << now.left[1] << ", " << now.left[2] << ", "
                     << now.left[3] << "; fastest " << now.fastest << " m/s; " << now.inside
                     << " fluid particles inside a lattice");
    }
    const StepReport& last = sim->last_report();
    long left = 0;
    for (long n : now.left) left += n;
    // Every melted particle is fluid now, and counted; none was lost.
    CHECK(last.lost_particles == 0);
    CHECK(long(last.value("melted")) == kCubes * kParticlesPerCube - left);
    CHECK(now.fluid == long(last.value("emitted")) + long(last.value("melted")));
    // Measured (EPYC VM): green gone by 1.5 s; at 2 s, 100, 100 and 67 particles left of red,
    // yellow and blue. Without the correction against the lattices' faces (coupling.correction
    // off) fluid gets into them (21 particles at once) and warms them from inside: 95, 86 and 31
    // left.
    CHECK(now.left[0] == 0);
    CHECK(green_ahead);
    CHECK(now.left[3] < kParticlesPerCube * 3 / 4);
    CHECK(most_inside <= 4);
    CHECK(now.left[1] > now.left[3]);
    CHECK(now.left[2] > now.left[3]);
    CHECK(now.left[1] > kParticlesPerCube / 2);
    CHECK(now.left[2] > kParticlesPerCube / 2);
    // The heavy cubes stay on the floor (their lattice's mean height started at 0.048 m).
    CHECK(now.centre_y[1] < 0.06);
    CHECK(now.centre_y[2] < 0.06);
    // The streams leave at 2 m/s and fall 0.45 m: 3.6 m/s at the floor (the paper: |v|max 3.85).
    CHECK(fastest < 4.5);
}
