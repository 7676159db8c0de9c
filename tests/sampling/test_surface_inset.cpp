// How far an elastic or rigid object's surface particles sit inside its faces
// (sampling/surface_inset.hpp): the full depth on a thick box, half the thickness on a plate
// thinner than twice the depth, the depth measured along each SBP's own normal, and bad input.
#include <algorithm>
#include <cmath>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling/surface_inset.hpp"
#include "sampling/surface_sampler.hpp"

using namespace mw;

namespace {
struct Range {
    double lo = 1e300, hi = -1e300;
    void add(double v) { lo = std::min(lo, v), hi = std::max(hi, v); }
};
}  // namespace

TEST_CASE("surface insets: the depth on a thick box, half the thickness on a thin plate") {
    const double r0 = 0.02, depth = 0.6 * r0;
    // A 0.2 m cube: every SBP is at least 0.2 m from the opposite face.
    const TriangleMesh cube = make_box(Vec3d(0.2, 0.2, 0.2));
    const SurfaceParticles on_cube = sample_surface(cube, r0);
    Range cube_insets;
    for (double inset : surface_insets(cube, on_cube, depth)) cube_insets.add(inset);
    MESSAGE("cube: insets " << cube_insets.lo / r0 << " to " << cube_insets.hi / r0 << " r0");
    CHECK(cube_insets.lo == doctest::Approx(depth).epsilon(1e-12));
    CHECK(cube_insets.hi == doctest::Approx(depth).epsilon(1e-12));

    // A plate r0 thick (0.2 x 0.02 x 0.2 m): its top and bottom SBPs sit half the thickness in
    // (the ray meets the other face r0 away, in float), so the two sides meet in the middle and
    // never cross; its rim's SBPs, 0.2 m across, the full depth.
    const TriangleMesh plate = make_box(Vec3d(0.2, r0, 0.2));
    const SurfaceParticles on_plate = sample_surface(plate, r0);
    const std::vector<double> plate_insets = surface_insets(plate, on_plate, depth);
    REQUIRE(plate_insets.size() == on_plate.count());
    Range faces, rim;
    for (std::size_t k = 0; k < on_plate.count(); ++k)
        (std::fabs(on_plate.normals[k].y()) > 0.5 ? faces : rim).add(plate_insets[k]);
    MESSAGE("plate: faces " << faces.lo / r0 << " to " << faces.hi / r0 << " r0, rim " << rim.lo / r0 << " to "
                            << rim.hi / r0 << " r0");
    CHECK(faces.lo == doctest::Approx(r0 / 2).epsilon(1e-5));
    CHECK(faces.hi == doctest::Approx(r0 / 2).epsilon(1e-5));
    CHECK(rim.lo == doctest::Approx(depth).epsilon(1e-12));

    // No depth: nothing set in; a negative or non-finite one is refused.
    for (double inset : surface_insets(cube, on_cube, 0.0)) CHECK(inset == 0);
    CHECK_THROWS_AS(surface_insets(cube, on_cube, -r0), InputError);
    CHECK_THROWS_AS(surface_insets(cube, on_cube, std::nan("")), InputError);
}
