// Signed distance grids of 2D outlines (sampling/outline_distance.hpp): a square against its
// analytic distance in the plane, a ring's hole outside, the two layers equal, sealed edges, and
// the node budget.
#include <algorithm>
#include <cmath>
#include <utility>

#include <doctest/doctest.h>

#include "sampling/outline.hpp"
#include "sampling/outline_distance.hpp"

using namespace mw;

namespace {

// The exact signed distance in the plane to the square [-h, h]².
double square_distance(double x, double y, double h) {
    const double qx = std::clamp(x, -h, h), qy = std::clamp(y, -h, h);
    const double outside = std::hypot(x - qx, y - qy);
    if (outside > 0) return outside;
    return -std::min({x + h, h - x, y + h, h - y});
}

}  // namespace

TEST_CASE("outline distance grid of a square: every node equals its exact distance in the plane, on both layers") {
    const TriangleMesh square = make_outline_from_spec("rectangle:x=0.2,y=0.2");
    const double spacing = 0.01, band = 0.01, margin = band + 2 * spacing, h = 0.1;
    const SignedDistanceGrid sdf = signed_distance_outline(square, spacing, band, 0);
    REQUIRE(sdf.distance.size() == sdf.grid.count());
    CHECK(sdf.exit_triangles == 4);
    CHECK(sdf.grid.dims[2] == 2);
    CHECK(sdf.grid.origin.z() == doctest::Approx(-0.5 * spacing));
    for (int a = 0; a < 2; ++a) {
        CHECK(sdf.grid.origin[a] <= -h - margin + 1e-12);
        CHECK(sdf.grid.origin[a] + (sdf.grid.dims[a] - 1) * spacing >= h + margin - 1e-12);
    }
    const std::size_t nx = std::size_t(sdf.grid.dims[0]), layer = nx * std::size_t(sdf.grid.dims[1]);
    double worst = 0;
    std::size_t inside = 0, layers_differ = 0;
    for (std::size_t id = 0; id < layer; ++id) {
        const Vec3d p = sdf.grid.position(int(id % nx), int(id / nx), 0);
        worst = std::max(worst, std::abs(sdf.distance[id] - square_distance(p.x(), p.y(), h)));
        inside += sdf.distance[id] < 0;
        layers_differ += sdf.distance[id] != sdf.distance[id + layer];
    }
    CHECK(worst < 1e-12);
    CHECK(inside > 0);
    CHECK(layers_differ == 0);
}

TEST_CASE("outline distance grid: a ring's hole is outside, an edge sealed is not measured, a budget coarsens") {
    // A ring 0.1 m in radius with a 0.03 m wall: the centre lies in the hole, 0.07 m from the wall.
    const TriangleMesh ring = make_outline_from_spec("ring:radius=0.1,wall=0.03,segments=256");
    const SignedDistanceGrid r = signed_distance_outline(ring, 0.005, 0.01, 0);
    const auto at = [&](const SignedDistanceGrid& g, double x, double y) {
        const int i = int(std::lround((x - g.grid.origin.x()) / g.grid.spacing));
        const int j = int(std::lround((y - g.grid.origin.y()) / g.grid.spacing));
        const Vec3d p = g.grid.position(i, j, 0);
        return std::pair<Vec3d, double>(p, g.distance[std::size_t(j) * std::size_t(g.grid.dims[0]) + std::size_t(i)]);
    };
    // (Named copies, not structured bindings, which clang 14 cannot capture in doctest's checks.)
    const std::pair<Vec3d, double> centre = at(r, 0, 0);
    CHECK(centre.second == doctest::Approx(0.07 - centre.first.head<2>().norm()).epsilon(1e-3));
    const std::pair<Vec3d, double> wall = at(r, 0.085, 0);  // in the wall, 0.015 m from both circles
    // Inside the wall, by its distance to the nearer circle (the 256-gon within 1e-5 m of it).
    const double from_centre = wall.first.head<2>().norm();
    CHECK(wall.second < 0);
    CHECK(wall.second == doctest::Approx(-std::min(0.1 - from_centre, from_centre - 0.07)).epsilon(2e-3));

    // The square with its bottom edge sealed (standing on a floor): a node below that edge's
    // middle measures to the sides' ends, not to the edge.
    const TriangleMesh square = make_outline_from_spec("rectangle:x=0.2,y=0.2");
    const SealedFace bottom = [](const Vec3d& a, const Vec3d& b, const Vec3d&) {
        return a.y() < -0.0999 && b.y() < -0.0999;
    };
    const SignedDistanceGrid sealed = signed_distance_outline(square, 0.01, 0.01, 0, bottom);
    CHECK(sealed.exit_triangles == 3);
    const std::pair<Vec3d, double> below = at(sealed, 0, -0.12);
    CHECK(below.second == doctest::Approx(std::hypot(0.1, below.first.y() + 0.1)));
    const SealedFace all = [](const Vec3d&, const Vec3d&, const Vec3d&) { return true; };
    CHECK(signed_distance_outline(square, 0.01, 0.01, 0, all).distance.empty());

    // A budget of 200 nodes coarsens the grid to fit it.
    const SignedDistanceGrid coarse = signed_distance_outline(square, 0.001, 0.01, 200);
    CHECK(coarse.grid.count() <= 200);
    CHECK(coarse.grid.spacing > 0.001);
}
