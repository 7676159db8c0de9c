// Meshes to particles: IBP volumes and placement, SBP coverage and embedding, GP links, and the
// inside/outside test on closed and open meshes.
#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "sampling/inside_outside.hpp"
#include "sampling/kdtree.hpp"
#include "sampling/obj_loader.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling/solid_sample.hpp"
#include "sampling/winding_number.hpp"
#include "sampling_helpers.hpp"

using namespace mw;

namespace {

// Largest distance from `probes` random surface points (own seed) to the nearest SBP.
double independent_largest_gap(const TriangleMesh& mesh, const std::vector<Vec3d>& sbp, std::size_t probes) {
    const auto pts = random_surface_points(mesh, probes, 987654321);
    PointTree tree(sbp);
    double worst = 0;
    for (const auto& p : pts) worst = std::max(worst, tree.nearest(p.position).second);
    return worst;
}

// IBPs with fewer than 26 one-ring neighbours: any IBP cluster outside the body, even a
// large one, has such IBPs on its own border, so checking these checks them all.
std::vector<std::size_t> border_ibps(const InnerParticles& ibp) {
    std::vector<std::size_t> out;
    for (std::size_t p = 0; p < ibp.count(); ++p)
        if (ibp.neighbor_offsets[p + 1] - ibp.neighbor_offsets[p] < 26) out.push_back(p);
    return out;
}

// Counts border IBPs whose generalized winding number is below 1/2. The hierarchical evaluation
// (accurate to about 1e-2) screens them; every one within 0.2 of 1/2 gets the exact O(triangles)
// sum, so the verdict is the exact winding number's.
std::size_t border_ibps_outside(const TriangleMesh& mesh, const InnerParticles& ibp) {
    const auto border = border_ibps(ibp);
    const FastWindingNumber fast(mesh);
    std::size_t outside = 0, exact = 0;
#pragma omp parallel for reduction(+ : outside, exact) schedule(dynamic, 16)
    for (long i = 0; i < static_cast<long>(border.size()); ++i) {
        const Vec3d& p = ibp.positions[border[static_cast<std::size_t>(i)]];
        double w = fast.evaluate(p);
        if (std::abs(w - 0.5) < 0.2) {
            w = winding_number(mesh, p);
            ++exact;
        }
        if (w < 0.5) ++outside;
    }
    MESSAGE(border.size() << " border IBPs checked, " << exact << " with the exact winding number");
    return outside;
}

void check_sbp_embedding(const TriangleMesh& mesh, const SurfaceParticles& sbp, double r0) {
    double worst = 0, worst_normal = 0;
    for (std::size_t s = 0; s < sbp.count(); ++s) {
        const Vec3d& b = sbp.barycentric[s];
        REQUIRE(b.minCoeff() >= -1e-12);
        REQUIRE(std::abs(b.sum() - 1.0) < 1e-12);
        worst = std::max(worst, (surface_position(mesh, sbp.triangles[s], b) - sbp.positions[s]).norm());
        worst_normal = std::max(worst_normal, (triangle_normal(mesh, std::size_t(sbp.triangles[s])) - sbp.normals[s]).norm());
    }
    CHECK(worst <= 1e-6 * r0);
    CHECK(worst_normal < 1e-12);
}

}  // namespace

TEST_CASE("sphere of radius 10 r0: IBP volume, no IBP outside, coverage, normals, embedding") {
    const double r0 = 0.1, R = 1.0;
    const TriangleMesh sphere = make_sphere(R, 5);
    const SolidSample s = sample_solid(sphere, r0, 2.5 * r0);
    const double exact = 4.0 / 3.0 * M_PI * R * R * R;
    const double ibp_volume = double(s.ibp.count()) * r0 * r0 * r0;
    MESSAGE("sphere: " << s.ibp.count() << " IBPs, volume " << ibp_volume << " vs " << exact << ", " << s.sbp.count()
                       << " SBPs, largest gap " << s.stats.largest_gap / r0 << " r0");
    CHECK(std::abs(ibp_volume - exact) <= 0.03 * exact);
    double farthest = 0;
    for (const Vec3d& p : s.ibp.positions) farthest = std::max(farthest, p.norm());
    CHECK(farthest < R);
    // None missing either: every lattice point inside the polyhedron's inscribed sphere is an IBP.
    double r_in = R;
    for (std::size_t t = 0; t < sphere.triangles.size(); ++t)
        r_in = std::min(r_in, std::abs(triangle_normal(sphere, t).dot(sphere.corner(t, 0))));
    std::size_t must = 0;
    const LatticeGrid& g = s.ibp.grid;
    for (int k = 0; k < g.dims[2]; ++k)
        for (int j = 0; j < g.dims[1]; ++j)
            for (int i = 0; i < g.dims[0]; ++i) must += g.position(i, j, k).norm() < r_in;
    std::size_t inner_ibps = 0;
    for (const Vec3d& p : s.ibp.positions) inner_ibps += p.norm() < r_in;
    CHECK(inner_ibps == must);
    // Coverage: the sampler's own check and an independent, denser one.
    CHECK(s.stats.largest_gap <= 0.6 * r0);
    const double gap = independent_largest_gap(sphere, s.sbp.positions, 400000);
    MESSAGE("independent largest gap " << gap / r0 << " r0 over 400000 probes");
    CHECK(gap <= 0.6 * r0);
    for (std::size_t i = 0; i < s.sbp.count(); ++i) {
        REQUIRE(s.sbp.normals[i].dot(s.sbp.positions[i].normalized()) > 0.99);
        REQUIRE(std::abs(s.sbp.positions[i].norm() - R) < 0.01 * R);
    }
    check_sbp_embedding(s.geometry, s.sbp, r0);
    // The thinning: no two SBPs (all face outward here) closer than 0.5 r0, so about 2.6 per r0²
    // (docs/sampling.md) and never more than a hexagonal packing at 0.5 r0 allows (4.6 per r0²);
    // at least the 1.54 per r0² that covering at 0.5 r0 needs.
    const PointTree sbp_tree(s.sbp.positions);
    std::vector<std::pair<std::uint32_t, double>> close;
    std::size_t crowded = 0;
    for (const Vec3d& p : s.sbp.positions) {
        sbp_tree.within(p, 0.5 * r0 * (1 - 1e-9), close);
        crowded += close.size() > 1;  // itself only
    }
    CHECK(crowded == 0);
    const double per_r0_squared = double(s.sbp.count()) / (4 * M_PI * R * R / (r0 * r0));
    MESSAGE("sphere: " << per_r0_squared << " SBPs per r0^2");
    CHECK(per_r0_squared >= 1.54);
    // The upper bound is a cost bound, not the packing limit (that one, 4.62 per r0², is the spacing
    // check above): docs/sampling.md quotes about 2.6 SBPs per r0² and this sphere gives 2.51, so 3.0
    // (20% over) fails a sampler that drifts toward denser packings, which would cost every step more
    // boundary particles for no better coverage.
    CHECK(per_r0_squared <= 3.0);
    // Symmetric lattice: the centred lattice puts the sphere centre between points.
    CHECK(s.ibp.grid.origin.x() == doctest::Approx(-0.95));
}

TEST_CASE("hollow box with walls 2 r0 thick: two IBP layers in every wall, none in the cavity") {
    const double r0 = 0.05;
    for (const double outer : {10 * r0, 10.37 * r0}) {
        CAPTURE(outer / r0);
        const TriangleMesh box = make_hollow_box(Vec3d(outer, outer, outer), 2 * r0);
        const SolidSample s = sample_solid(box, r0, 2.5 * r0);
        const double half_outer = 0.5 * outer, half_inner = 0.5 * outer - 2 * r0;
        for (const Vec3d& p : s.ibp.positions) {
            REQUIRE(p.cwiseAbs().maxCoeff() < half_outer);       // inside the outer box
            REQUIRE(p.cwiseAbs().maxCoeff() > half_inner);       // not in the cavity
        }
        // Along every lattice line through the box: exactly two IBPs in each wall it crosses
        // perpendicularly. Count per (j, k) line along x where the line is inside the cavity's
        // y-z footprint: it must cross two walls of two layers each, so 4 IBPs.
        const LatticeGrid& g = s.ibp.grid;
        std::vector<int> per_line(std::size_t(g.dims[1]) * std::size_t(g.dims[2]), 0);
        for (const auto& c : s.ibp.lattice) ++per_line[std::size_t(c[2]) * std::size_t(g.dims[1]) + std::size_t(c[1])];
        int checked = 0;
        for (int k = 0; k < g.dims[2]; ++k)
            for (int j = 0; j < g.dims[1]; ++j) {
                const Vec3d p = g.position(0, j, k);
                if (std::abs(p.y()) < half_inner && std::abs(p.z()) < half_inner) {
                    CHECK(per_line[std::size_t(k) * std::size_t(g.dims[1]) + std::size_t(j)] == 4);
                    ++checked;
                }
            }
        CHECK(checked >= 25);
        if (outer == 10 * r0) {
            CHECK(s.ibp.count() == 1000 - 216);  // the full 10^3 lattice minus the 6^3 cavity
            CHECK(s.ibp.grid.dims == std::array<int, 3>{10, 10, 10});
            CHECK(s.stats.ibp_volume == doctest::Approx(signed_volume(box)));
        }
        CHECK(s.stats.largest_gap <= 0.6 * r0);
        // Both faces of each wall carry SBPs with their own outward normals.
        std::size_t cavity_facing = 0;
        for (std::size_t i = 0; i < s.sbp.count(); ++i)
            if (s.sbp.positions[i].cwiseAbs().maxCoeff() < half_inner + 1e-9) {
                ++cavity_facing;
                REQUIRE(s.sbp.normals[i].dot(s.sbp.positions[i]) < 0);  // inner faces point into the cavity
            }
        CHECK(cavity_facing > 100);
    }
}

TEST_CASE("one-ring connectivity of the lattice") {
    const double r0 = 0.1;
    const SolidSample s = sample_solid(make_box(Vec3d(0.5, 0.5, 0.5)), r0, 2.5 * r0);
    REQUIRE(s.ibp.count() == 125);
    std::size_t full = 0;
    std::set<std::pair<int, int>> edges;
    for (std::size_t p = 0; p < s.ibp.count(); ++p) {
        const int n = s.ibp.neighbor_offsets[p + 1] - s.ibp.neighbor_offsets[p];
        if (n == 26) ++full;
        for (int e = s.ibp.neighbor_offsets[p]; e < s.ibp.neighbor_offsets[p + 1]; ++e) {
            const int q = s.ibp.neighbor_indices[std::size_t(e)];
            REQUIRE(q != int(p));
            const auto a = s.ibp.lattice[p], b = s.ibp.lattice[std::size_t(q)];
            REQUIRE(std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])}) == 1);
            edges.insert({int(p), q});
        }
    }
    CHECK(full == 27);  // the 3^3 interior
    for (const auto& e : edges) REQUIRE(edges.count({e.second, e.first}) == 1);  // symmetric
    // Corners have 7 neighbours.
    CHECK(s.ibp.neighbor_offsets[1] - s.ibp.neighbor_offsets[0] == 7);
}

TEST_CASE("GP links: the IBPs within h with cubic-spline weights") {
    const double r0 = 0.1, h = 0.25;
    const TriangleMesh mesh = make_torus(0.6, 0.3, 24, 12);
    const SolidSample s = sample_solid(mesh, r0, h);
    // The GPs: the vertices of the sampler's mesh, refined so that no edge exceeds r0 (the
    // torus's own vertices first).
    const TriangleMesh& geometry = s.geometry;
    REQUIRE(s.gp.count() == geometry.vertices.size());
    REQUIRE(s.gp.count() > mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) REQUIRE(geometry.vertices[v] == mesh.vertices[v]);
    CHECK(cubic_spline_w(0.0, h) == doctest::Approx(8.0 / (M_PI * h * h * h)));
    CHECK(cubic_spline_w(h, h) == 0.0);
    CHECK(cubic_spline_w(0.5 * h, h) == doctest::Approx(8.0 / (M_PI * h * h * h) * 0.25));
    for (std::size_t g = 0; g < s.gp.count(); ++g) {
        std::vector<int> expected;
        for (std::size_t p = 0; p < s.ibp.count(); ++p)
            if ((s.ibp.positions[p] - geometry.vertices[g]).norm() < h) expected.push_back(int(p));
        const std::vector<int> got(s.gp.ibp.begin() + s.gp.offsets[g], s.gp.ibp.begin() + s.gp.offsets[g + 1]);
        if (expected.empty()) continue;  // orphan: linked to its nearest IBP
        REQUIRE(got == expected);
        for (int e = s.gp.offsets[g]; e < s.gp.offsets[g + 1]; ++e) {
            const double r = (s.ibp.positions[std::size_t(s.gp.ibp[std::size_t(e)])] - geometry.vertices[g]).norm();
            REQUIRE(s.gp.weight[std::size_t(e)] == doctest::Approx(cubic_spline_w(r, h)));
            REQUIRE(s.gp.weight[std::size_t(e)] > 0);
        }
    }
    CHECK(s.stats.gps_without_ibp == 0);
}

TEST_CASE("inside/outside: torus hole, nested shells, and an open box") {
    const TriangleMesh torus = make_torus(1.0, 0.3, 64, 32);
    const std::vector<Vec3d> q = {{0, 0, 0}, {1, 0, 0}, {0, 0, -1.25}, {1.35, 0, 0}, {0, 0.35, 1}, {0, 0.25, 1}};
    const auto in = classify_points(torus, q);
    CHECK(in == std::vector<std::uint8_t>{0, 1, 1, 0, 0, 1});
    // An open cube (top face removed): the body is still inside (winding number 5/6 at the
    // centre), the outside still outside, although every upward ray escapes through the hole.
    TriangleMesh open = make_box(Vec3d(1, 1, 1));
    std::vector<std::array<int, 3>> kept;
    for (std::size_t t = 0; t < open.triangles.size(); ++t)
        if (triangle_normal(open, t).y() < 0.5) kept.push_back(open.triangles[t]);
    open.triangles = kept;
    REQUIRE(edge_report(open).boundary_edges == 4);
    CHECK(winding_number(open, Vec3d(0, 0, 0)) == doctest::Approx(5.0 / 6.0).epsilon(1e-9));
    const auto open_in = classify_points(open, {{0, 0, 0}, {0.3, -0.3, 0.3}, {0, 0.8, 0}, {0, -0.8, 0}, {2, 0, 0}});
    CHECK(open_in == std::vector<std::uint8_t>{1, 1, 0, 0, 0});
    const InnerParticles ibp = sample_inner(open, 0.1);
    CHECK(ibp.count() == 1000);  // the whole 10^3 lattice: every point has winding number > 1/2
    for (const Vec3d& p : ibp.positions) REQUIRE(p.cwiseAbs().maxCoeff() < 0.5);
}

TEST_CASE("spot.obj (closed): IBP volume within 5%, no IBP outside") {
    if (mwtest::missing_mesh("spot.obj")) return;
    const TriangleMesh spot = load_obj(mwtest::mesh_dir() + "/spot.obj");
    const double r0 = 0.05;
    const SolidSample s = sample_solid(spot, r0, 2.5 * r0);
    MESSAGE("spot: " << s.stats.ibp_count << " IBPs, volume " << s.stats.ibp_volume << " vs mesh " << s.stats.mesh_volume
                     << ", " << s.stats.sbp_count << " SBPs, gap " << s.stats.largest_gap / r0 << " r0, "
                     << s.timings.total << " s");
    CHECK(s.stats.closed);
    CHECK(s.stats.ambiguous_points == 0);  // every direction agrees on a closed mesh
    CHECK(std::abs(s.stats.ibp_volume - s.stats.mesh_volume) <= 0.05 * s.stats.mesh_volume);
    CHECK(border_ibps_outside(spot, s.ibp) == 0);
    CHECK(s.stats.largest_gap <= 0.6 * r0);
    check_sbp_embedding(s.geometry, s.sbp, r0);
}

TEST_CASE("stanford-bunny.obj (open, 223 boundary edges): body filled, no IBP outside") {
    if (mwtest::missing_mesh("stanford-bunny.obj")) return;
    const TriangleMesh bunny = load_obj(mwtest::mesh_dir() + "/stanford-bunny.obj");
    const double r0 = 0.006;  // about 26 r0 across: coarse, to keep the test fast
    const SolidSample s = sample_solid(bunny, r0, 2.5 * r0);
    MESSAGE("bunny: " << s.stats.ibp_count << " IBPs, volume " << s.stats.ibp_volume << " vs signed volume "
                      << s.stats.mesh_volume << ", " << s.stats.ambiguous_points << " ambiguous lattice points, "
                      << s.stats.sbp_count << " SBPs, gap " << s.stats.largest_gap / r0 << " r0, " << s.timings.total << " s");
    CHECK_FALSE(s.stats.closed);
    CHECK(s.stats.boundary_edges == 223);
    CHECK(s.stats.mesh_volume == doctest::Approx(7.70e-4).epsilon(0.01));
    CHECK(std::abs(s.stats.ibp_volume - s.stats.mesh_volume) <= 0.05 * s.stats.mesh_volume);
    CHECK(border_ibps_outside(bunny, s.ibp) == 0);
    CHECK(s.stats.largest_gap <= 0.6 * r0);
    check_sbp_embedding(s.geometry, s.sbp, r0);
}

TEST_CASE("inside/outside does not depend on the mesh's scale (the ray tracer works in float)") {
    // Embree multiplies three coordinates in single precision: unscaled, a box of side 7e25 gave
    // infinite hit distances and one of side 3e-25 underflowed, both classified as empty. (Sides
    // around 1e13 made the sampler loop for ever: tests/sampling_cli checks those under a timeout.)
    const TriangleMesh unit = make_box(Vec3d(1, 1, 1));
    const InnerParticles reference = sample_inner(unit, 0.1);
    REQUIRE(reference.count() == 1000);
    for (const double scale : {3e-25, 1e-13, 7e25}) {
        CAPTURE(scale);
        TriangleMesh box = make_box(Vec3d(scale, scale, scale));
        const InnerParticles ibp = sample_inner(box, 0.1 * scale);
        CHECK(ibp.count() == 1000);
        CHECK(ibp.classification.ambiguous == 0);
        CHECK(ibp.lattice == reference.lattice);
        const std::vector<Vec3d> probes = {{0, 0, 0}, {0.49 * scale, 0.3 * scale, -0.2 * scale}, {0.51 * scale, 0, 0},
                                           {2 * scale, 2 * scale, 2 * scale}, {1e6 * scale, 0, 0}};
        CHECK(classify_points(box, probes) == std::vector<std::uint8_t>{1, 1, 0, 0, 0});
    }
}

TEST_CASE("spacings the ray tracer cannot handle are refused with one line, never an abort") {
    const TriangleMesh sphere = make_sphere(1.0, 3);
    using mwtest::error_of;
    // Larger than the mesh: the lattice lines would start 1e20 away, which made Embree assert.
    CHECK(error_of([&] { sample_solid(sphere, 1e20, 2.5e20); }).find("is larger than the mesh itself") != std::string::npos);
    CHECK(error_of([&] { sample_solid(sphere, 2.5, 6); }).find("is larger than the mesh itself") != std::string::npos);
    CHECK(sample_solid(sphere, 1.5, 3.75).stats.ibp_count == 1);  // one lattice point, at the centre
    // Called directly, the lattice classifier refuses such lines too (its exception crosses the
    // OpenMP region instead of terminating the process).
    CHECK(error_of([&] { sample_inner(sphere, 1e20); }).find("beyond what the single-precision ray tracer handles") !=
          std::string::npos);
    // Finer than single precision resolves: a needle 2e5 spacings long.
    const TriangleMesh needle = make_box(Vec3d(2e5, 1, 1));
    CHECK(error_of([&] { sample_solid(needle, 1.0, 2.5); }).find("too fine for the single-precision ray tracer") !=
          std::string::npos);
    // More surface candidates than 32-bit numbering holds: an InputError, refused before allocating.
    TriangleMesh triangle;
    triangle.source = "triangle";
    triangle.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    triangle.triangles = {{0, 1, 2}};
    CHECK(error_of([&] { sample_surface(triangle, 1e-5); }).rfind("triangle: the surface needs ", 0) == 0);
}
