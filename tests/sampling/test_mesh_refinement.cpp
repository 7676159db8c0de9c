// A moving object's mesh refined for its GPs (sampling/mesh_refinement.hpp): no edge longer than
// asked, the same closed surface, and every point of the input found again on the refined mesh.
#include <algorithm>
#include <cmath>
#include <string>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "sampling/mesh_refinement.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling/solid_sample.hpp"
#include "sampling/surface_sampler.hpp"

using namespace mw;

namespace {

double longest_edge(const TriangleMesh& mesh) {
    double longest = 0;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        for (int e = 0; e < 3; ++e) longest = std::max(longest, (mesh.corner(t, e) - mesh.corner(t, (e + 1) % 3)).norm());
    return longest;
}

// Every refined triangle lies on the input's surface: checked for a box by its faces' planes.
void check_same_surface(const TriangleMesh& input, const TriangleMesh& refined) {
    CHECK(surface_area(refined) == doctest::Approx(surface_area(input)).epsilon(1e-12));
    CHECK(signed_volume(refined) == doctest::Approx(signed_volume(input)).epsilon(1e-12));
    const EdgeReport edges = edge_report(refined);
    CHECK(edges.closed());
    CHECK(edges.consistently_oriented());
    for (std::size_t v = 0; v < input.vertices.size(); ++v) REQUIRE(refined.vertices[v] == input.vertices[v]);
}

}  // namespace

TEST_CASE("refining a box: no edge longer than asked, the same closed surface, its corners first") {
    const TriangleMesh box = make_box(Vec3d(0.3, 0.2, 0.1));
    for (const double limit : {0.2, 0.05, 0.02, 0.013}) {
        CAPTURE(limit);
        const RefinedMesh refined = refine_long_edges(box, limit);
        CHECK(longest_edge(refined.mesh) <= limit);
        check_same_surface(box, refined.mesh);
        // Every vertex on the box's surface: one coordinate at a face's plane, none beyond.
        for (const Vec3d& v : refined.mesh.vertices) {
            const Vec3d q = v.cwiseAbs().cwiseQuotient(Vec3d(0.15, 0.1, 0.05));
            REQUIRE(q.maxCoeff() == doctest::Approx(1.0).epsilon(1e-12));
        }
        // Each pass's children account for every triangle of the next.
        for (std::size_t p = 0; p < refined.passes.size(); ++p) {
            const auto& split = refined.passes[p];
            const std::size_t next = p + 1 < refined.passes.size() ? refined.passes[p + 1].first_child.size() - 1
                                                                  : refined.mesh.triangles.size();
            REQUIRE(std::size_t(split.first_child.back()) == next);
            REQUIRE(split.child_corners.size() == next);
        }
    }
}

TEST_CASE("refining keeps a mesh already fine enough as it is") {
    const TriangleMesh sphere = make_sphere(0.1, 3);
    const double longest = longest_edge(sphere);
    const RefinedMesh refined = refine_long_edges(sphere, longest * 1.01);
    CHECK(refined.passes.empty());
    CHECK(refined.mesh.vertices == sphere.vertices);
    CHECK(refined.mesh.triangles == sphere.triangles);
    // Just under its longest edge, some split: still a closed sphere mesh of the same area.
    const RefinedMesh finer = refine_long_edges(sphere, longest * 0.99);
    CHECK(longest_edge(finer.mesh) <= longest * 0.99);
    CHECK(finer.mesh.triangles.size() > sphere.triangles.size());
    CHECK(surface_area(finer.mesh) == doctest::Approx(surface_area(sphere)).epsilon(1e-12));
    CHECK(edge_report(finer.mesh).closed());
}

TEST_CASE("a point of the input is found again on the refined mesh, at the same position") {
    const TriangleMesh torus = make_torus(0.3, 0.1, 12, 6);  // long thin triangles: all three cases of split
    const RefinedMesh refined = refine_long_edges(torus, 0.01);
    REQUIRE(refined.passes.size() >= 3);
    double worst = 0, worst_weight = 0;
    for (const SurfacePoint& p : random_surface_points(torus, 5000, 7)) {
        int triangle = p.triangle;
        Vec3d bary = p.barycentric;
        refined.locate(triangle, bary);
        REQUIRE(triangle >= 0);
        REQUIRE(std::size_t(triangle) < refined.mesh.triangles.size());
        worst = std::max(worst, (surface_position(refined.mesh, triangle, bary) - p.position).norm());
        worst_weight = std::min(worst_weight, bary.minCoeff());
        REQUIRE(std::abs(bary.sum() - 1) < 1e-12);
    }
    CHECK(worst < 1e-14);
    CHECK(worst_weight > -1e-12);
}

TEST_CASE("refinement that would take too many triangles, or a bad limit, is one clear error") {
    TriangleMesh box = make_box(Vec3d(1, 1, 1));
    box.source = "big_box.obj";
    try {
        refine_long_edges(box, 0.001, 100000);
        FAIL("no error");
    } catch (const InputError& e) {
        const std::string message = e.what();
        CHECK(message.find("big_box.obj") != std::string::npos);
        CHECK(message.find("100000 triangles") != std::string::npos);
    }
    CHECK_THROWS_AS(refine_long_edges(box, 0), InputError);
    CHECK_THROWS_AS(refine_long_edges(box, -1), InputError);
    CHECK_THROWS_AS(refine_long_edges(box, std::nan("")), InputError);
}

TEST_CASE("sample_solid: the GPs are the refined mesh's vertices, and the SBPs' weights refer to it") {
    const double r0 = 0.02, h = 0.04;
    const TriangleMesh box = make_box(Vec3d(0.3, 0.2, 0.1));
    const SolidSample coarse = [&] {
        SampleOptions options;
        options.geometry_max_edge = 0;
        return sample_solid(box, r0, h, options);
    }();
    const SolidSample s = sample_solid(box, r0, h);  // the default: no edge longer than r0
    CHECK(coarse.gp.count() == 8);
    CHECK(coarse.geometry.triangles == box.triangles);
    CHECK(longest_edge(s.geometry) <= r0);
    check_same_surface(box, s.geometry);
    CHECK(s.gp.count() == s.geometry.vertices.size());
    CHECK(s.stats.gp_count == s.gp.count());
    CHECK(s.stats.geometry_triangles == s.geometry.triangles.size());
    CHECK(s.stats.triangles == 12);
    // The refinement moves no SBP: the same particles, each found on its refined triangle.
    REQUIRE(s.sbp.count() == coarse.sbp.count());
    double worst = 0;
    for (std::size_t k = 0; k < s.sbp.count(); ++k) {
        REQUIRE(s.sbp.positions[k] == coarse.sbp.positions[k]);
        worst = std::max(worst, (surface_position(s.geometry, s.sbp.triangles[k], s.sbp.barycentric[k]) -
                                 s.sbp.positions[k]).norm());
        REQUIRE(s.sbp.barycentric[k].minCoeff() > -1e-12);
    }
    CHECK(worst < 1e-14);
    // The GPs link IBPs within h as before: a GP in the middle of a face has some.
    CHECK(s.stats.gps_without_ibp == 0);
}
