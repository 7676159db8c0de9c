// Signed distance grids of meshes (sampling/signed_distance.hpp): the point–triangle distance,
// grid values against exact distances (a box's analytic one, a sphere mesh's brute-force one),
// the sign against the winding number, open meshes, the node budget and bad meshes.
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "sampling/inside_outside.hpp"
#include "sampling/obj_loader.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling/signed_distance.hpp"
#include "sampling_helpers.hpp"

using namespace mw;

namespace {

// The exact signed distance to an axis-aligned box [lo, hi]: outside, to its nearest point;
// inside, minus the distance to its nearest face.
double box_distance(const Vec3d& p, const Vec3d& lo, const Vec3d& hi) {
    const Vec3d q = p.cwiseMax(lo).cwiseMin(hi);
    const double outside = (p - q).norm();
    if (outside > 0) return outside;
    return -std::min((p - lo).minCoeff(), (hi - p).minCoeff());
}

// Brute force over every triangle.
double mesh_distance(const TriangleMesh& m, const Vec3d& p) {
    double best = 1e300;
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
        best = std::min(best, point_triangle_distance(p, m.corner(t, 0), m.corner(t, 1), m.corner(t, 2)));
    return best;
}

Vec3d node(const LatticeGrid& g, std::size_t id) {
    const std::size_t nx = std::size_t(g.dims[0]), ny = std::size_t(g.dims[1]);
    return g.position(int(id % nx), int((id / nx) % ny), int(id / (nx * ny)));
}

}  // namespace

TEST_CASE("point-triangle distance: face, edge, vertex and degenerate regions") {
    const Vec3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    CHECK(point_triangle_distance(Vec3d(0.2, 0.2, 0.5), a, b, c) == doctest::Approx(0.5));   // above the face
    CHECK(point_triangle_distance(Vec3d(0.2, 0.2, -0.3), a, b, c) == doctest::Approx(0.3));  // below it
    CHECK(point_triangle_distance(Vec3d(0.5, -0.4, 0.3), a, b, c) == doctest::Approx(0.5));  // beyond edge ab
    CHECK(point_triangle_distance(Vec3d(1, 1, 0), a, b, c) == doctest::Approx(std::sqrt(0.5)));  // beyond bc
    CHECK(point_triangle_distance(Vec3d(-0.3, -0.4, 0), a, b, c) == doctest::Approx(0.5));  // beyond vertex a
    CHECK(point_triangle_distance(Vec3d(2, 0, 0), a, b, c) == doctest::Approx(1.0));        // beyond vertex b
    // A triangle folded onto a segment is that segment.
    CHECK(point_triangle_distance(Vec3d(0.5, 1, 0), a, b, Vec3d(0.5, 0, 0)) == doctest::Approx(1.0));
    CHECK(point_triangle_distance(Vec3d(3, 0, 0), a, a, a) == doctest::Approx(3.0));
}

TEST_CASE("signed distance grid of a box: every node equals the box's exact signed distance") {
    const Vec3d size(0.3, 0.1, 0.2);
    TriangleMesh box = make_box(size);
    const Vec3d lo = -0.5 * size, hi = 0.5 * size;
    const double spacing = 0.01, band = 0.01, margin = band + 2 * spacing;
    const SignedDistanceGrid sdf = signed_distance_grid(box, spacing, band, 0);
    REQUIRE(sdf.distance.size() == sdf.grid.count());
    CHECK(sdf.grid.spacing == spacing);
    // The grid reaches the margin past the box on every side.
    for (int a = 0; a < 3; ++a) {
        CHECK(sdf.grid.origin[a] <= lo[a] - margin + 1e-12);
        CHECK(sdf.grid.origin[a] + (sdf.grid.dims[a] - 1) * spacing >= hi[a] + margin - 1e-12);
    }
    double worst = 0;
    std::size_t inside = 0;
    for (std::size_t id = 0; id < sdf.grid.count(); ++id) {
        const double exact = box_distance(node(sdf.grid, id), lo, hi);
        worst = std::max(worst, std::abs(sdf.distance[id] - exact));
        inside += sdf.distance[id] < 0;
    }
    MESSAGE("box: " << sdf.grid.count() << " nodes, " << inside << " inside, largest error " << worst << " m");
    CHECK(worst < 1e-12);
    CHECK(inside > 0);

    // An inward-oriented copy gives the same field: the builder orients meshes outward first.
    flip_orientation(box);
    const SignedDistanceGrid flipped = signed_distance_grid(box, spacing, band, 0);
    CHECK(flipped.distance == sdf.distance);
}

TEST_CASE("signed distance grid of a sphere mesh: exact distances to its triangles, signed by the winding number") {
    const double radius = 0.12;
    const TriangleMesh sphere = make_sphere(radius, 3);
    const double margin = 0.02;  // no band: two nodes
    const SignedDistanceGrid sdf = signed_distance_grid(sphere, 0.01, 0, 0);
    double longest_edge = 0;
    for (std::size_t t = 0; t < sphere.triangle_count(); ++t)
        longest_edge = std::max(longest_edge, (sphere.corner(t, 0) - sphere.corner(t, 1)).norm());
    std::mt19937 rng(7);
    std::uniform_int_distribution<std::size_t> pick(0, sdf.grid.count() - 1);
    double worst_near = 0, worst_far = 0, worst_analytic = 0;
    int near = 0, far = 0;
    for (int k = 0; k < 600; ++k) {
        const std::size_t id = pick(rng);
        const Vec3d p = node(sdf.grid, id);
        const double brute = mesh_distance(sphere, p);
        const bool inside = winding_number(sphere, p) > 0.5;
        CHECK((sdf.distance[id] < 0) == inside);
        const double error = std::abs(sdf.distance[id]) - brute;
        CHECK(error >= -1e-12);  // never nearer than the surface is
        if (brute <= margin) {
            worst_near = std::max(worst_near, std::abs(error));
            ++near;
            // The icosphere's facets lie inside the sphere by at most the sagitta of their chords.
            worst_analytic = std::max(worst_analytic, std::abs(sdf.distance[id] - (p.norm() - radius)));
        } else {
            worst_far = std::max(worst_far, error);
            ++far;
        }
    }
    MESSAGE("sphere: within the margin (" << near << " nodes) largest error against the brute-force distance "
                                          << worst_near << " m, against the analytic sphere " << worst_analytic
                                          << " m; farther (" << far << " nodes, the nearest vertex's distance) "
                                          << worst_far << " m, longest edge " << longest_edge << " m");
    CHECK(near > 50);
    CHECK(far > 50);
    CHECK(worst_near < 1e-12);
    CHECK(worst_far < longest_edge);
    CHECK(worst_analytic < 0.02 * radius);
}

TEST_CASE("signed distance grid: a node budget coarsens the grid to fit it") {
    const TriangleMesh box = make_box(Vec3d(1, 1, 1));
    const SignedDistanceGrid fine = signed_distance_grid(box, 0.05, 0.1, 0);
    const SignedDistanceGrid capped = signed_distance_grid(box, 0.05, 0.1, 4000);
    CHECK(fine.grid.count() > 4000);
    CHECK(capped.grid.count() <= 4000);
    CHECK(capped.grid.count() > 2000);  // not coarser than it has to be
    CHECK(capped.grid.spacing > 0.05);
    // The band and two of the coarser nodes past the box.
    for (int a = 0; a < 3; ++a) CHECK(capped.grid.origin[a] <= -0.5 - 0.1 - 2 * capped.grid.spacing + 1e-12);
    // A budget too small for any grid, or nonsense arguments, are refused.
    CHECK_THROWS_AS(signed_distance_grid(box, 0.05, 0.1, 7), std::invalid_argument);
    CHECK_THROWS_AS(signed_distance_grid(box, 0, 0.1, 0), std::invalid_argument);
}

TEST_CASE("signed distance grid: vertices no triangle uses are ignored") {
    TriangleMesh box = make_box(Vec3d(0.2, 0.2, 0.2));
    const SignedDistanceGrid clean = signed_distance_grid(box, 0.02, 0.02, 0);
    box.vertices.push_back(Vec3d(0.2, 0, 0));  // 0.1 m off the +x face, in no triangle
    const SignedDistanceGrid stray = signed_distance_grid(box, 0.02, 0.02, 0);
    CHECK(stray.grid.dims == clean.grid.dims);
    CHECK(stray.distance == clean.distance);
}

TEST_CASE("signed distance grid: sealed faces are no way out, but still tell inside from outside") {
    // A 0.2 m cube standing on the plane y = -0.1 (its bottom face), that face sealed.
    const TriangleMesh box = make_box(Vec3d(0.2, 0.2, 0.2));
    const SealedFace on_floor = [](const Vec3d& a, const Vec3d& b, const Vec3d& c) {
        return std::max({a.y(), b.y(), c.y()}) <= -0.1 + 1e-9;
    };
    const SignedDistanceGrid sdf = signed_distance_grid(box, 0.01, 0.01, 0, on_floor);
    CHECK(sdf.exit_triangles == 10);  // 12 less the bottom's two
    const Vec3d lo(-0.1, -0.1, -0.1), hi(0.1, 0.1, 0.1);
    double worst_inside = 0, worst_outside = 0;
    for (std::size_t id = 0; id < sdf.grid.count(); ++id) {
        const Vec3d p = node(sdf.grid, id);
        if (p.y() < lo.y() + 1e-9) continue;  // on or below the floor: no fluid there
        const double exact = box_distance(p, lo, hi);
        if (exact >= 0) {
            worst_outside = std::max(worst_outside, std::abs(sdf.distance[id] - exact));
        } else {
            // Inside: the distance to the sides and the top only.
            const double to_exit =
                std::min({p.x() - lo.x(), hi.x() - p.x(), p.z() - lo.z(), hi.z() - p.z(), hi.y() - p.y()});
            worst_inside = std::max(worst_inside, std::abs(sdf.distance[id] + to_exit));
        }
    }
    CHECK(worst_inside < 1e-12);
    CHECK(worst_outside < 1e-12);
    // Every face sealed: no grid.
    const SignedDistanceGrid none =
        signed_distance_grid(box, 0.01, 0.01, 0, [](const Vec3d&, const Vec3d&, const Vec3d&) { return true; });
    CHECK(none.exit_triangles == 0);
    CHECK(none.distance.empty());
}

TEST_CASE("signed distance grid: a broken mesh is an InputError naming it") {
    TriangleMesh broken = make_box(Vec3d(1, 1, 1));
    broken.source = "broken.obj";
    broken.vertices[0].x() = std::nan("");
    const std::string message = mwtest::error_of([&] { signed_distance_grid(broken, 0.1, 0.1, 0); });
    CHECK(message.find("broken.obj") != std::string::npos);
}

TEST_CASE("signed distance grid of an open scan (the bunny): the sign follows the generalized winding number") {
    if (mwtest::missing_mesh("stanford-bunny.obj")) return;
    const TriangleMesh bunny = load_obj(mwtest::mesh_dir() + "/stanford-bunny.obj");
    const Aabb box = bounding_box(bunny);
    const double spacing = box.extent().maxCoeff() / 30;
    const SignedDistanceGrid sdf = signed_distance_grid(bunny, spacing, 0, 0);
    std::mt19937 rng(3);
    std::uniform_int_distribution<std::size_t> pick(0, sdf.grid.count() - 1);
    int agree = 0, total = 0;
    for (int k = 0; k < 300; ++k) {
        const std::size_t id = pick(rng);
        const Vec3d p = node(sdf.grid, id);
        const double w = winding_number(bunny, p);
        if (std::abs(w - 0.5) < 0.1) continue;  // across a hole, where "inside" is a vote
        ++total;
        agree += (sdf.distance[id] < 0) == (w > 0.5);
    }
    MESSAGE("bunny: " << sdf.grid.count() << " nodes in " << sdf.seconds << " s; sign agrees with the winding number at "
                      << agree << " of " << total << " nodes");
    CHECK(agree == total);
}
