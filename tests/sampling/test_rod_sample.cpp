// A rod's centreline to particles (sampling/rod_sample.hpp): a polyline resampled at equal steps of
// at most r0 along its length, its length shared among its nodes, each linked to its neighbours,
// two SBPs a segment; lines that are not lines, or too short for three nodes, refused. A curved
// centreline read from an OBJ polyline ("l").
#include <cmath>
#include <cstdio>
#include <string>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "sampling/obj_loader.hpp"
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

TEST_CASE("An OBJ polyline is a rod's centreline, its points in the line's order") {
    // A quarter circle of radius 0.2 m in 8 chords, its vertices written out of order and the
    // line putting them back; a texture index on one point, a relative index on the last.
    std::string text = "# quarter circle\n";
    const int order[9] = {4, 0, 8, 2, 6, 1, 3, 7, 5};  // vertex k of the file is point order[k]
    int file_index[9];
    for (int k = 0; k < 9; ++k) {
        const double a = 0.5 * M_PI * order[k] / 8;
        char line[96];
        std::snprintf(line, sizeof line, "v %.17g %.17g 0\n", 0.2 * std::cos(a), 0.2 * std::sin(a));
        text += line;
        file_index[order[k]] = k + 1;
    }
    text += "vt 0 0\nl";
    for (int point = 0; point < 9; ++point) {
        if (point == 1) text += " " + std::to_string(file_index[point]) + "/1";
        else if (point == 8) text += " " + std::to_string(file_index[point] - 10);  // counted back from the end
        else text += " " + std::to_string(file_index[point]);
    }
    text += "\n";
    const TriangleMesh line = parse_obj(text, "arc.obj");
    REQUIRE(line.vertices.size() == 9);
    CHECK(line.triangles.empty());
    // To the OBJ reader's precision (its coordinates are floats: 0.2 to about 1e-8).
    for (int point = 0; point < 9; ++point) {
        const double a = 0.5 * M_PI * point / 8;
        CHECK((line.vertices[std::size_t(point)] - Vec3d(0.2 * std::cos(a), 0.2 * std::sin(a), 0)).norm() < 2e-8);
    }
    // Resampled along the arc: the chords' length (0.3137 m) in 16 steps at r0 = 0.02.
    const RodSample rod = sample_rod(line, 0.02);
    const double chords = 16 * 0.2 * std::sin(0.5 * M_PI / 16);
    CHECK(rod.length == doctest::Approx(chords).epsilon(1e-7));
    CHECK(rod.nodes.size() == 17);
    CHECK((rod.nodes.front() - Vec3d(0.2, 0, 0)).norm() < 2e-8);
    CHECK((rod.nodes.back() - Vec3d(0, 0.2, 0)).norm() < 2e-8);
}

TEST_CASE("A bad OBJ polyline is refused with its line number") {
    auto error = [](const std::string& text) {
        try {
            parse_obj(text, "rod.obj");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    const std::string points = "v 0 0 0\nv 0.1 0 0\nv 0.2 0 0\n";
    CHECK(error(points + "l 1\n") == "rod.obj: the line has 1 point, a line needs at least 2 (line 4: 'l 1')");
    CHECK(error(points + "l 1 2 7\n").find("the line refers to vertex 7, but the file has 3 vertices") != std::string::npos);
    CHECK(error(points + "l 1 0\n").find("vertex 0") != std::string::npos);
    CHECK(error(points + "l 1 x\n").find("'x' is not a vertex index") != std::string::npos);
    CHECK(error(points + "l 1 -4\n").find("only 3 vertices precede it") != std::string::npos);
    CHECK(error(points + "l 1 2 3 1\n").find("visits vertex 1 twice") != std::string::npos);
    CHECK(error(points + "l 1 2\nl 2 3\n") ==
          "rod.obj: a second line (\"l\"); a rod is one line: join them into one (line 5: 'l 2 3')");
    CHECK(error(points + "l 1 2 3\n") == "accepted");
}
