// 2D objects' shapes (sampling/outline.hpp) and their particles (sampling/outline_sample.hpp):
// procedural outlines enclose their analytic areas; the IBPs fill them at one per r0², the SBPs
// line them at r0 with outward normals (holes' edges oriented the other way), the GPs are the
// corners with edges split to r0; outline files are read, and broken ones refused on one line
// naming the file and the fault.
#include <cmath>
#include <fstream>
#include <string>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "sampling/outline.hpp"
#include "sampling/outline_sample.hpp"
#include "tests/scratch_dir.hpp"

using namespace mw;

namespace {

std::string refusal_of_text(const std::string& name, const std::string& text) {
    const std::string path = (mw_test::scratch_dir("meltwater_outline") / name).string();
    std::ofstream(path) << text;
    try {
        load_outline(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}

// The SBP normal points away from the solid: a step along it leaves the outline, a step against it enters.
bool normals_outward(const TriangleMesh& outline, const SolidSample& s, double step) {
    const auto edges = outline_edges(outline);
    for (std::size_t k = 0; k < s.sbp.count(); ++k) {
        const Vec3d out = s.sbp.positions[k] + step * s.sbp.normals[k], in = s.sbp.positions[k] - step * s.sbp.normals[k];
        if (inside_outline(outline, edges, out.x(), out.y()) || !inside_outline(outline, edges, in.x(), in.y())) return false;
    }
    return true;
}

}  // namespace

TEST_CASE("procedural outlines enclose their areas, holes subtracted") {
    CHECK(outline_area(make_outline_from_spec("rectangle:x=0.2,y=0.1")) == doctest::Approx(0.02).epsilon(1e-12));
    CHECK(outline_area(make_outline_from_spec("hollow_rectangle:x=0.2,y=0.1,wall=0.02")) ==
          doctest::Approx(0.02 - 0.16 * 0.06).epsilon(1e-12));
    CHECK(outline_area(make_outline_from_spec("hollow_rectangle:x=0.2,y=0.1,wall=0.02,open_top=1")) ==
          doctest::Approx(0.02 - 0.16 * 0.08).epsilon(1e-12));
    // A regular 64-gon: n/2 r² sin(2π/n).
    const double polygon = 32 * 0.01 * std::sin(2 * M_PI / 64);
    CHECK(outline_area(make_outline_from_spec("circle:radius=0.1")) == doctest::Approx(polygon).epsilon(1e-12));
    CHECK(outline_area(make_outline_from_spec("ring:radius=0.1,wall=0.03")) ==
          doctest::Approx(polygon * (1 - 0.49)).epsilon(1e-12));
    CHECK(is_outline_spec("ring:radius=1"));
    CHECK_FALSE(is_outline_spec("sphere:radius=1"));
}

TEST_CASE("a rectangle's particles: r0 squares inside, SBPs at r0 along its edges, GPs on edges of r0") {
    const double r0 = 0.01;
    const TriangleMesh rect = make_outline_from_spec("rectangle:x=0.2,y=0.1");
    const SolidSample s = sample_outline(rect, r0, 2 * r0);
    CHECK(s.ibp.count() == 200);  // 20 x 10, each the centre of an r0 square
    CHECK(s.stats.ibp_volume == doctest::Approx(outline_area(rect)));
    CHECK(s.sbp.count() == 60);   // the perimeter 0.6 m at r0
    CHECK(s.gp.count() == 60);    // 4 corners and 56 edge points
    for (const auto& x : s.ibp.positions) CHECK(x.z() == 0);
    // Interior IBPs have the full one-ring of 8; a corner one 3.
    int full = 0, corner = 0;
    for (std::size_t p = 0; p < s.ibp.count(); ++p) {
        const int n = s.ibp.neighbor_offsets[p + 1] - s.ibp.neighbor_offsets[p];
        full += n == 8;
        corner += n == 3;
    }
    CHECK(full == 18 * 8);
    CHECK(corner == 4);
    CHECK(normals_outward(rect, s, 1e-4));
    // Every SBP lies on its edge, on the solid's side of it by nothing (the face), half an edge from a corner.
    for (std::size_t k = 0; k < s.sbp.count(); ++k) {
        const auto& t = s.geometry.triangles[std::size_t(s.sbp.triangles[k])];
        CHECK(t[2] == t[0]);
        const Vec3d on = s.sbp.barycentric[k][0] * s.geometry.vertices[t[0]] + s.sbp.barycentric[k][1] * s.geometry.vertices[t[1]];
        CHECK((on - s.sbp.positions[k]).norm() < 1e-12);
    }
    // Twice the SBPs at half the spacing.
    OutlineSampleOptions dense;
    dense.surface_spacing = 0.5;
    CHECK(sample_outline(rect, r0, 2 * r0, dense).sbp.count() == 120);
}

TEST_CASE("hollow shapes: IBPs only in the wall, the hole's SBPs facing into the hole") {
    const double r0 = 0.01;
    const TriangleMesh box = make_outline_from_spec("hollow_rectangle:x=0.2,y=0.1,wall=0.02");
    const SolidSample s = sample_outline(box, r0, 2 * r0);
    CHECK(s.ibp.count() == 200 - 16 * 6);
    CHECK(s.sbp.count() == 60 + 44);
    CHECK(normals_outward(box, s, 1e-4));
    const TriangleMesh ring = make_outline_from_spec("ring:radius=0.1,wall=0.03");
    const SolidSample r = sample_outline(ring, r0, 2 * r0);
    // The lattice squares approximate the area to within the rim's share.
    CHECK(double(r.ibp.count()) * r0 * r0 == doctest::Approx(outline_area(ring)).epsilon(0.05));
    CHECK(normals_outward(ring, r, 1e-4));
    // Insets: a rigid wall 2 r0 thick sets its SBPs in at most r0 (half of it).
    const std::vector<double> inset = outline_insets(s.geometry, s.sbp, 0.5 * r0);
    for (double d : inset) CHECK(d == doctest::Approx(0.5 * r0));
    // Deeper than the wall: half the wall's 2 r0 wherever the inward ray crosses the wall into the
    // hole, the full depth where it runs along a side wall to the far side (two SBPs by each
    // outer corner on each side: 16).
    const std::vector<double> thin = outline_insets(s.geometry, s.sbp, 3 * r0);
    int half_wall = 0, full = 0;
    for (double d : thin) {
        half_wall += std::fabs(d - r0) < 1e-12;
        full += std::fabs(d - 3 * r0) < 1e-12;
    }
    CHECK(half_wall == 104 - 16);
    CHECK(full == 16);
}

TEST_CASE("outline files: loops between blank lines, comments, and one line for each fault") {
    const std::string path = (mw_test::scratch_dir("meltwater_outline") / "l.outline").string();
    std::ofstream(path) << "# an L\n0 0\n0.2 0\n0.2 0.1\n0.1 0.1\n0.1 0.3\n0 0.3\n\n";
    const TriangleMesh l = load_outline(path);
    CHECK(l.triangles.size() == 6);
    CHECK(outline_area(l) == doctest::Approx(0.04));
    CHECK(refusal_of_text("two.outline", "0 0\n1 0\n").find("2 point(s); a loop needs at least 3") != std::string::npos);
    CHECK(refusal_of_text("word.outline", "0 0\n1 x\n0 1\n").find("word.outline:2: expected a point") != std::string::npos);
    CHECK(refusal_of_text("three.outline", "0 0 0\n1 0\n0 1\n").find(":1: expected a point") != std::string::npos);
    CHECK(refusal_of_text("bow.outline", "0 0\n1 1\n1 0\n0 1\n").find("cross") != std::string::npos);
    CHECK(refusal_of_text("repeat.outline", "0 0\n1 0\n0 1\n0 0\n").find("zero-length edge") != std::string::npos);
    CHECK(refusal_of_text("empty.outline", "# nothing\n").find("holds no loop") != std::string::npos);
    // A loop on a line beside a good one: its edges share corners, so only the fold shows it.
    CHECK(refusal_of_text("line.outline", "0 0\n1 0\n1 1\n0 1\n\n2 0\n3 0\n4 0\n").find("loop 2 folds back") !=
          std::string::npos);
    CHECK(refusal_of_text("overlap.outline", "0 0\n1 0\n1 1\n0 1\n\n0.5 0.5\n2 0.5\n2 2\n").find("cross") != std::string::npos);
    try {
        load_outline("/nonexistent/shape.outline");
        FAIL("a missing file was read");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()).find("cannot open") != std::string::npos);
    }
    CHECK_THROWS_AS(make_outline_from_spec("hollow_rectangle:x=0.1,y=0.1,wall=0.05"), InputError);
    CHECK_THROWS_AS(make_outline_from_spec("circle:radius=0.1,segments=2"), InputError);
    CHECK_THROWS_AS(make_outline_from_spec("square:x=1"), InputError);
}
