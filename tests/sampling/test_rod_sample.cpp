// A rod's centreline to particles (sampling/rod_sample.hpp): a polyline resampled at equal steps of
// at most r0 along its length, its length shared among its nodes, each linked to its neighbours,
// two SBPs a segment; lines that are not lines, or too short for three nodes, refused.
#include <cmath>
#include <string>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling/rod_sample.hpp"

using namespace mw;

namespace {

std::string refusal(const TriangleMesh& mesh, double spacing = 0.02) {
    try {
        sample_rod(mesh, spacing);
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}

}  // namespace

TEST_CASE("A bent line is resampled at equal steps along its length, which its nodes share") {
    // An L: 0.1 m along x, then 0.05 m along y. 0.15 m at r0 = 0.02: 8 steps of 0.01875 m.
    TriangleMesh l;
    l.vertices = {Vec3d(0, 0, 0), Vec3d(0.1, 0, 0), Vec3d(0.1, 0.05, 0)};
    const RodSample s = sample_rod(l, 0.02);
    REQUIRE(s.nodes.size() == 9);
    CHECK(s.length == doctest::Approx(0.15));
    double along = 0, shared = 0;
    for (std::size_t k = 0; k < s.nodes.size(); ++k) {
        shared += s.node_length[k];
        if (k == 0) continue;
        along += (s.nodes[k] - s.nodes[k - 1]).norm();
        CHECK((s.nodes[k] - s.nodes[k - 1]).norm() <= 0.02 + 1e-12);
    }
    CHECK(shared == doctest::Approx(0.15));
    CHECK(along < 0.15);  // the node at the corner's either side cuts it
    CHECK((s.nodes.back() - Vec3d(0.1, 0.05, 0)).norm() < 1e-12);
    // Node 5 lies 0.09375 m along: on the first leg.
    CHECK((s.nodes[5] - Vec3d(0.09375, 0, 0)).norm() < 1e-12);
    // A chain: the ends have one neighbour, the others two.
    CHECK(s.graph_offsets[1] - s.graph_offsets[0] == 1);
    CHECK(s.graph_offsets[5] - s.graph_offsets[4] == 2);
    CHECK(s.graph_links[s.graph_offsets[4]] == 3);
    CHECK(s.graph_links[s.graph_offsets[4] + 1] == 5);
    REQUIRE(s.sbp.size() == 16);
    CHECK((s.sbp[0] - 0.75 * s.nodes[0] - 0.25 * s.nodes[1]).norm() < 1e-12);
    CHECK(s.sbp_segment[15] == 7);
    CHECK(s.sbp_fraction[15] == doctest::Approx(0.75));
}

TEST_CASE("A line of exactly n r0 keeps n steps of r0") {
    const RodSample s = sample_rod(make_line(0.5), 0.02);
    CHECK(s.nodes.size() == 26);
    CHECK((s.nodes[1] - s.nodes[0]).norm() == doctest::Approx(0.02));
}

TEST_CASE("A rod is a line of two or more distinct points, longer than r0 (three nodes)") {
    CHECK(refusal(make_box(Vec3d(0.1, 0.1, 0.1))).find("a rod is a line") != std::string::npos);
    CHECK(refusal(make_line(0.02)).find("a rod needs at least 3") != std::string::npos);
    CHECK(refusal(make_line(0.021)) == "accepted");  // three nodes 0.0105 m apart
    TriangleMesh repeated;
    repeated.vertices = {Vec3d(0, 0, 0), Vec3d(0, 0, 0), Vec3d(0.1, 0, 0)};
    CHECK(refusal(repeated).find("coincide") != std::string::npos);
    TriangleMesh one;
    one.vertices = {Vec3d(0, 0, 0)};
    CHECK(refusal(one).find("at least two points") != std::string::npos);
    TriangleMesh infinite;
    infinite.vertices = {Vec3d(std::nan(""), 0, 0), Vec3d(0.1, 0, 0)};
    CHECK(refusal(infinite).find("point 1 is not finite") != std::string::npos);
    CHECK(refusal(make_line(0.1), 0).find("spacing") != std::string::npos);
}
