// A cloth's sheet to particles (sampling/sheet_sample.hpp): a coarse sheet refined to edges of at
// most 1.5 r0, its area shared among its vertices, their edges as the regions' graph, SBPs on its
// triangles; sheets that are not open, manifold and consistently oriented refused.
#include <algorithm>
#include <string>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling/sheet_sample.hpp"

using namespace mw;

namespace {

std::string refusal(const TriangleMesh& mesh) {
    try {
        sample_sheet(mesh, 0.02);
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}

}  // namespace

TEST_CASE("A coarse sheet is refined to nodes about r0 apart, which share its area and are linked along its edges") {
    const TriangleMesh coarse = make_sheet(0.3, 0.2, 3, 2);  // 0.1 m quads: five times r0
    const SheetSample s = sample_sheet(coarse, 0.02);
    double area = 0, longest = 0;
    for (double a : s.node_area) area += a;
    CHECK(area == doctest::Approx(0.3 * 0.2).epsilon(1e-12));
    for (std::size_t t = 0; t < s.mesh.triangles.size(); ++t)
        for (int e = 0; e < 3; ++e) longest = std::max(longest, (s.mesh.corner(t, e) - s.mesh.corner(t, (e + 1) % 3)).norm());
    CHECK(longest <= kSheetMaxEdge * 0.02 + 1e-12);
    CHECK(s.mesh.vertices.size() > coarse.vertices.size());
    // The graph is the edges, both ways.
    REQUIRE(s.graph_offsets.size() == s.mesh.vertices.size() + 1);
    for (std::size_t v = 0; v < s.mesh.vertices.size(); ++v)
        for (std::uint32_t e = s.graph_offsets[v]; e < s.graph_offsets[v + 1]; ++e) {
            const std::uint32_t w = s.graph_links[e];
            CHECK(w != v);
            CHECK(std::binary_search(s.graph_links.begin() + s.graph_offsets[w], s.graph_links.begin() + s.graph_offsets[w + 1], std::uint32_t(v)));
        }
    CHECK(s.sbp.count() > s.mesh.vertices.size());
    for (const Vec3d& n : s.sbp.normals) CHECK(n.y() == doctest::Approx(1.0));
    CHECK(s.boundary_edges == 10);
}

TEST_CASE("A sheet that is closed, has an edge of three triangles, faces both ways or has a triangle of no area is refused") {
    CHECK(refusal(make_box(Vec3d(0.1, 0.1, 0.1))).find("the mesh is closed") != std::string::npos);
    TriangleMesh fin = make_sheet(0.1, 0.1, 1, 1);  // two triangles, and a third on their diagonal
    fin.vertices.emplace_back(0.0, 0.1, 0.0);
    fin.triangles.push_back({fin.triangles[0][0], fin.triangles[0][2], int(fin.vertices.size() - 1)});
    CHECK(refusal(fin).find("edge(s) are shared by more than two triangles") != std::string::npos);
    TriangleMesh flipped = make_sheet(0.1, 0.1, 1, 1);
    std::swap(flipped.triangles[1][0], flipped.triangles[1][1]);
    CHECK(refusal(flipped).find("not consistently oriented") != std::string::npos);
    TriangleMesh needle = make_sheet(0.1, 0.1, 1, 1);  // a third triangle with its corners on a line
    needle.vertices.emplace_back(0.2, 0.0, 0.05);
    needle.vertices.emplace_back(0.3, 0.0, 0.05);
    needle.triangles.push_back({int(needle.vertices.size() - 2), int(needle.vertices.size() - 1), int(needle.vertices.size() - 1)});
    CHECK(refusal(needle).find("has no area") != std::string::npos);
    CHECK(refusal(make_sheet(0.1, 0.1, 5, 5)) == "accepted");
}
