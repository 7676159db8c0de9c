// The velocity–position correction against the domain walls and static boxes
// (algorithms/wall_contact.hpp): the rule on single particles, where its bands lie, and a block
// driven into a wall or a box far faster than one Akinci layer can stop, with the correction and
// without.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "algorithms/wall_contact.hpp"
#include "simulation/factory.hpp"
#include "sampling/box_particles.hpp"
#include "sampling/fluid_clearance.hpp"
#include "sampling/wall_gap.hpp"
#include "test_setups.hpp"

using namespace mw;

TEST_CASE("wall contact: a particle moving outward inside the band is put back on its plane, with no normal speed") {
    const Real r0 = 0.02f, gap = Real(0.6) * r0;
    const WallContact walls = WallContact::for_domain({0, 0, 0}, {1, 1, 1}, gap, r0);
    // r0 from the first layer, which lies 0.6 r0 outside the faces: 0.4 r0 inside them.
    CHECK(walls.lo.y == doctest::Approx(0.4 * r0));
    CHECK(walls.hi.x == doctest::Approx(1 - 0.4 * r0));

    SUBCASE("moving into the floor: back to the plane, the normal speed gone, the tangential kept") {
        Vec3 x{0.5f, Real(0.1) * r0, 0.5f}, v{1.5f, -3, -0.5f};
        walls.correct(x, v);
        CHECK(x.y == doctest::Approx(0.4 * r0));
        CHECK(v.y == 0);
        CHECK(v.x == doctest::Approx(1.5));
        CHECK(v.z == doctest::Approx(-0.5));
        CHECK(x.x == doctest::Approx(0.5));
    }
    SUBCASE("in the band but leaving the wall: untouched") {
        Vec3 x{0.5f, Real(0.1) * r0, 0.5f}, v{0, 2, 0};
        walls.correct(x, v);
        CHECK(x.y == doctest::Approx(0.1 * r0));
        CHECK(v.y == doctest::Approx(2));
    }
    SUBCASE("outside the band, even fast towards a wall: untouched") {
        Vec3 x{0.5f, 0.5f, 0.5f}, v{-40, 40, 0};
        walls.correct(x, v);
        CHECK(x.x == doctest::Approx(0.5));
        CHECK(v.x == doctest::Approx(-40));
        CHECK(v.y == doctest::Approx(40));
    }
    SUBCASE("in a corner, behind two walls: both axes corrected") {
        Vec3 x{Real(1.1), Real(-0.05), 0.5f}, v{2, -2, 1};
        walls.correct(x, v);
        CHECK(x.x == doctest::Approx(1 - 0.4 * r0));
        CHECK(x.y == doctest::Approx(0.4 * r0));
        CHECK(v.x == 0);
        CHECK(v.y == 0);
        CHECK(v.z == doctest::Approx(1));
    }
    SUBCASE("inside PCISPH only the predicted position moves") {
        const Vec3 x = walls.correct_predicted(Vec3{0.5f, -0.01f, 0.5f}, Vec3{0, -1, 0});
        CHECK(x.y == doctest::Approx(0.4 * r0));
    }
    SUBCASE("non-finite positions and velocities are left for the guard") {
        const Real inf = std::numeric_limits<Real>::infinity();
        Vec3 x{0.5f, -inf, 0.5f}, v{0, -1, 0};
        walls.correct(x, v);
        CHECK(std::isinf(x.y));
        Vec3 y{0.5f, 0, 0.5f}, w{0, -inf, 0};
        walls.correct(y, w);
        CHECK(std::isinf(w.y));
    }
    SUBCASE("inactive (no walls): nothing moves") {
        const WallContact none;
        Vec3 x{0.5f, -1, 0.5f}, v{0, -1, 0};
        none.correct(x, v);
        CHECK(x.y == -1);
        CHECK(v.y == -1);
    }
}

TEST_CASE("wall contact: a fluid block touching a face starts on or beyond the plane, for every layer count") {
    // Fluid blocks start r0/2 inside the faces. With more layers the first one sits closer in
    // (0.475 r0 with two), and the band is then capped at the distance where that fluid rests,
    // so the correction never acts on a block at rest.
    const Real r0 = 0.02f;
    for (int layers = 1; layers <= 4; ++layers)
        for (const KernelKind kernel : {KernelKind::kCubicSpline, KernelKind::kWendlandC2})
            for (const Real h_in_r0 : {Real(2), Real(2.5)}) {
                const Real gap = rest_density_wall_gap(r0, h_in_r0 * r0, r0 / 2, layers, kernel);
                const WallContact walls = WallContact::for_domain({0, 0, 0}, {1, 1, 1}, gap, r0);
                CAPTURE(layers);
                CAPTURE(gap / r0);
                // At least 0.1 r0 of slack below where that fluid rests (r0/2 inside the face).
                CHECK(walls.lo.y <= Real(0.4) * r0 + 1e-7f);
                CHECK(walls.hi.y >= 1 - Real(0.4) * r0 - 1e-7f);
                // Never farther than r0 from the layer (the paper's distance), never outside the layer.
                CHECK(walls.lo.y + gap <= r0 * (1 + 1e-5f));
                CHECK(walls.lo.y + gap > 0);
                // One layer at h >= 2 r0 has that slack already: the band is the paper's r0.
                if (layers == 1 && kernel == KernelKind::kCubicSpline)
                    CHECK(walls.lo.y + gap == doctest::Approx(r0));
            }
}

TEST_CASE("wall contact: static boxes, with a band rounded at their edges") {
    const Real r0 = 0.02f;
    const ContactBox box{{0.4f, 0, 0.4f}, {0.6f, 0.2f, 0.6f}, r0};
    WallContact contact;  // no domain walls: the box alone
    contact.boxes = View<const ContactBox>{&box, 1};

    SUBCASE("above the top face, falling: back to r0 above it, the normal speed gone") {
        Vec3 x{0.5f, Real(0.2) + Real(0.3) * r0, 0.5f}, v{1, -4, 0};
        contact.correct(x, v);
        CHECK(x.y == doctest::Approx(0.2 + r0));
        CHECK(v.y == doctest::Approx(0).epsilon(1e-6));
        CHECK(v.x == doctest::Approx(1));
        CHECK(x.x == doctest::Approx(0.5));
    }
    SUBCASE("beside an edge, moving at it: put r0 from the edge along the diagonal") {
        const Real s = Real(0.5) * r0;  // 0.71 r0 from the top edge at x = 0.6, y = 0.2
        Vec3 x{Real(0.6) + s, Real(0.2) + s, 0.5f}, v{-1, -1, 0.5f};
        contact.correct(x, v);
        const Real off = r0 / std::sqrt(Real(2));
        CHECK(x.x == doctest::Approx(0.6 + off));
        CHECK(x.y == doctest::Approx(0.2 + off));
        // Only about 0: in a double build the float literals put the point a hair off the diagonal.
        CHECK(std::fabs(v.x) < 1e-5);
        CHECK(std::fabs(v.y) < 1e-5);
        CHECK(v.z == doctest::Approx(0.5));
    }
    SUBCASE("off the edge by more than r0, though within r0 of both faces' planes: untouched") {
        const Real s = Real(0.8) * r0;  // 1.13 r0 from the edge
        Vec3 x{Real(0.6) + s, Real(0.2) + s, 0.5f}, v{-1, -1, 0};
        contact.correct(x, v);
        CHECK(x.x == doctest::Approx(0.6 + s));
        CHECK(v.x == doctest::Approx(-1));
    }
    SUBCASE("inside the box: out through the nearest face") {
        Vec3 x{0.5f, Real(0.2) - Real(0.2) * r0, 0.45f}, v{0, -3, 0};
        contact.correct(x, v);
        CHECK(x.y == doctest::Approx(0.2 + r0));
        CHECK(v.y == doctest::Approx(0).epsilon(1e-6));
    }
    SUBCASE("inside the box, moving along its nearest face: still out through that face") {
        // Near the side face x = 0.6, falling: no velocity into that face, but inside is never right.
        Vec3 x{Real(0.6) - Real(0.1) * r0, 0.1f, 0.5f}, v{0, -3, 0};
        contact.correct(x, v);
        CHECK(x.x == doctest::Approx(0.6 + r0));
        CHECK(v.y == doctest::Approx(-3));  // tangential to that face: kept
    }
    SUBCASE("inside the box, already moving out: out through the nearest face, its speed kept") {
        Vec3 x{0.5f, Real(0.2) - Real(0.2) * r0, 0.45f}, v{0, 2, 0};
        contact.correct(x, v);
        CHECK(x.y == doctest::Approx(0.2 + r0));
        CHECK(v.y == doctest::Approx(2));
    }
    SUBCASE("near the box but leaving it: untouched") {
        Vec3 x{0.5f, Real(0.2) + Real(0.3) * r0, 0.5f}, v{0, 2, 0};
        contact.correct(x, v);
        CHECK(x.y == doctest::Approx(0.2 + 0.3 * r0));
        CHECK(v.y == doctest::Approx(2));
    }
}

TEST_CASE("wall contact: a static box's band stays inside the closest the carve lets fluid start") {
    // The scene builder keeps fluid kFluidClearance r0 from a box's particles, which sit on a
    // square grid of r0/2 on its faces: above the middle of a grid square that is 0.935 r0 from
    // the face. A band wider than that would hold fluid that starts at rest.
    const Real r0 = 0.02f;
    const Real carved = carved_face_distance(Real(kFluidClearance) * r0, r0 / 2);
    CHECK(carved / r0 == doctest::Approx(std::sqrt(0.875)).epsilon(1e-5));
    const Real gap = rest_density_wall_gap(r0, 2 * r0, r0 / 2, 1, KernelKind::kCubicSpline);
    CHECK(contact_distance(gap, r0) == doctest::Approx(r0));  // rests at 1.1 r0: the paper's r0
    CHECK(std::min(contact_distance(gap, r0), carved) / r0 == doctest::Approx(0.935).epsilon(1e-3));
    // The particles sample_solid_box places: none closer to the face grid than the grid spacing.
    const std::vector<Vec3> face = sample_solid_box({0, 0, 0}, {0.2f, 0.2f, 0.2f}, r0 / 2, 1);
    const Vec3 middle{Real(0.1) + r0 / 4, Real(0.2) + carved, Real(0.1) + r0 / 4};  // over a square's middle
    Real nearest = 1e9f;
    for (const Vec3& p : face) nearest = std::min(nearest, norm(p - middle));
    CHECK(nearest >= r0 * (1 - 1e-4f));  // the carve keeps it
}

namespace {

struct Impact {
    long lost = 0;
    Real lowest = 1e30f;        // the closest any fluid particle came to the wall (or box), over every step
    double energy_ratio = 0;    // largest kinetic energy after the first step over the first's
};

// A 0.12 m cube of fluid at 20 m/s towards the x = 0 wall of a 0.6 m box, at a fixed 2 ms: two
// particle spacings a step, ten times what one Akinci layer stops within a step. With
// `static_box`, the cube is aimed instead at a static box (one layer) 0.1 m in front of that wall.
Impact drive_into_wall(bool correction, bool static_box = false) {
    const Real r0 = 0.02f;
    const Vec3 lo = static_box ? Vec3{0.3f, 0.1f, 0.24f} : Vec3{0.1f, 0.1f, 0.24f};
    SimulationSetup setup = test::fluid_in_box({0, 0, 0}, {0.6f, 0.6f, 0.6f}, lo,
                                               lo + Vec3{0.12f, 0.12f, 0.12f}, r0, 0.002f);
    setup.params.gravity = {0, 0, 0};
    setup.params.boundary.correction = correction;
    if (static_box) {
        // A band of r0 (contact_box: a layer gap of r0 leaves it at r0, as does a carve of r0).
        const StaticBoxFaces box{{0.1f, 0.02f, 0.1f}, {0.2f, 0.3f, 0.5f}, r0, r0};
        for (const Vec3& p : sample_solid_box(box.lo, box.hi, r0 / 2, 1)) {
            setup.position.push_back(p);
            setup.velocity.push_back(Vec3{0, 0, 0});
            setup.type.push_back(kStaticBoundary);
            setup.object.push_back(0);
        }
        setup.params.boundary.static_boxes.push_back(box);
    }
    // How far a particle is from the face the cube is driven at, the wall's (x = 0), or from the
    // box (0 inside it: the fluid also flows round the box, past its far side).
    const StaticBoxFaces target = static_box ? setup.params.boundary.static_boxes[0] : StaticBoxFaces{};
    auto clearance = [&](Vec3 x) {
        if (!static_box) return x.x;
        const Vec3 q{std::clamp(x.x, target.lo.x, target.hi.x), std::clamp(x.y, target.lo.y, target.hi.y),
                     std::clamp(x.z, target.lo.z, target.hi.z)};
        return norm(x - q);
    };
    for (std::size_t i = 0; i < setup.type.size(); ++i)
        if (setup.type[i] == kFluid) setup.velocity[i] = Vec3{-20, 0, 0};
    auto sim = create_openmp_simulation(setup, 0);
    Impact impact;
    double first_energy = 0;
    HostParticles particles;
    for (int step = 0; step < 25; ++step) {
        sim->step();
        const StepReport& r = sim->last_report();
        impact.lost = r.lost_particles;
        if (step == 0) first_energy = r.kinetic_energy;
        impact.energy_ratio = std::max(impact.energy_ratio, r.kinetic_energy / first_energy);
        sim->download(particles);
        for (std::size_t i = 0; i < particles.type.size(); ++i)
            if (particles.type[i] == kFluid && std::isfinite(particles.position[i].x))
                impact.lowest = std::min(impact.lowest, clearance(particles.position[i]));
    }
    MESSAGE(std::string(static_box ? "static box" : "domain wall") << ", correction "
            << std::string(correction ? "on" : "off") << ": " << impact.lost << " lost, closest "
                          << impact.lowest / r0 << " r0, largest kinetic energy / first step's " << impact.energy_ratio);
    return impact;
}

}  // namespace

TEST_CASE("wall contact: a block driven into a wall at 20 m/s stays inside with the correction, and breaks out without") {
    const Real r0 = 0.02f;
    const Impact without = drive_into_wall(false);
    CHECK(without.lost > 0);
    const Impact with = drive_into_wall(true);
    CHECK(with.lost == 0);
    // No particle ever closer than r0 to the wall's layer (about 0.6 r0 outside the face).
    const Real gap = rest_density_wall_gap(r0, 2 * r0, r0 / 2, 1, KernelKind::kCubicSpline);
    CHECK(with.lowest >= (r0 - gap) * (1 - 1e-4f));
    CHECK(with.lowest < Real(0.41) * r0);  // and some did reach the plane
    // The normal rule is inelastic: the impact takes energy out and never puts any in.
    CHECK(with.energy_ratio <= 1.0 + 1e-6);
}

TEST_CASE("wall contact: a block driven into a static box at 20 m/s stays out of it with the correction") {
    const Real r0 = 0.02f;
    const Impact without = drive_into_wall(false, true);
    CHECK(without.lowest == 0);  // a particle got inside the box, past its layer
    const Impact with = drive_into_wall(true, true);
    CHECK(with.lost == 0);
    // Never inside, and well off the layer. The rule acts on where a step ends, so a particle
    // that passes an edge in a straight step can end within the band already moving away, which
    // the rule leaves alone: the closest is not r0 (measured: 1.00 r0 in float, 0.60 r0 in a
    // double build, where the chaotic splash goes otherwise).
    CHECK(with.lowest > Real(0.25) * r0);
    CHECK(with.lowest < Real(1.01) * r0);
    // Not asserted: the kinetic energy. The fluid squirts round the box's edges at this step (two
    // spacings a step) and PCISPH can gain energy there with the correction as without it
    // (measured over the first step's: 1.00 and 1.45 in float, 1.32 and 1.45 in double).
}

