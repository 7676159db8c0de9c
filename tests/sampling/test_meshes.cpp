// Meshes: procedural makers, transforms, OBJ loading and every kind of bad input.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "sampling/mesh.hpp"
#include "sampling/obj_loader.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling_helpers.hpp"
#include "tests/scratch_dir.hpp"

using namespace mw;
using mwtest::error_of;

namespace {
// This program's scratch directory (tests/scratch_dir.hpp).
std::filesystem::path scratch_dir() { return mw_test::scratch_dir("mw_sampling_test"); }

void check_closed_outward(const TriangleMesh& m, double expected_volume, double rel_tol) {
    const EdgeReport e = edge_report(m);
    CHECK(e.boundary_edges == 0);
    CHECK(e.nonmanifold_edges == 0);
    CHECK(e.misoriented_edges == 0);
    CHECK(signed_volume(m) == doctest::Approx(expected_volume).epsilon(rel_tol));
    CHECK_NOTHROW(validate_mesh(m, true));
}
}  // namespace

TEST_CASE("procedural meshes are closed, outward and have the right volume") {
    check_closed_outward(make_box(Vec3d(1, 2, 3)), 6.0, 1e-12);
    check_closed_outward(make_hollow_box(Vec3d(1, 1, 1), 0.2), 1.0 - 0.6 * 0.6 * 0.6, 1e-12);
    check_closed_outward(make_hollow_box(Vec3d(1, 1, 1), 0.2, true), 1.0 - 0.6 * 0.6 * 0.8, 1e-12);
    check_closed_outward(make_sphere(2.0, 5), 4.0 / 3.0 * M_PI * 8.0, 2e-3);
    check_closed_outward(make_cylinder(0.5, 2.0, 256), M_PI * 0.25 * 2.0, 1e-3);
    check_closed_outward(make_torus(1.0, 0.25, 256, 128), 2 * M_PI * M_PI * 1.0 * 0.0625, 1e-3);
    check_closed_outward(make_stairs(4, 1.0, 0.3, 0.2), 1.0 * 0.3 * 0.2 * (4 * 5 / 2), 1e-12);
    const TriangleMesh sheet = make_sheet(1, 2, 4, 8);
    CHECK(edge_report(sheet).boundary_edges == 2 * (4 + 8));
    CHECK(surface_area(sheet) == doctest::Approx(2.0));
    CHECK(triangle_normal(sheet, 0).y() == doctest::Approx(1.0));
    CHECK_THROWS_AS(validate_mesh(sheet, true), InputError);  // encloses nothing
    CHECK_NOTHROW(validate_mesh(sheet, false));
    // Centred on the origin.
    const Aabb b = bounding_box(make_stairs(3, 1, 1, 1));
    CHECK(b.center().norm() < 1e-12);
}

TEST_CASE("procedural specs and their errors") {
    const TriangleMesh s = make_procedural_from_spec("sphere:radius=0.5,subdivisions=3");
    CHECK(s.triangles.size() == 20 * 64);
    CHECK(bounding_box(s).extent().x() == doctest::Approx(1.0));
    CHECK(is_procedural_spec("hollow_box:wall=0.1"));
    CHECK_FALSE(is_procedural_spec("bunny.obj"));
    CHECK(error_of([] { make_procedural_from_spec("pyramid"); }).find("unknown procedural mesh 'pyramid'") != std::string::npos);
    CHECK(error_of([] { make_procedural_from_spec("box:depth=2"); }).find("unknown parameter 'depth'") != std::string::npos);
    CHECK(error_of([] { make_procedural_from_spec("box:x=abc"); }).find("not a number") != std::string::npos);
    CHECK(error_of([] { make_procedural_from_spec("hollow_box:wall=0.6"); }).find("wall") != std::string::npos);
    CHECK(error_of([] { make_procedural_from_spec("sphere:radius=-1"); }).find("radius") != std::string::npos);
}

TEST_CASE("transforms scale, rotate, translate and keep the orientation outward") {
    TriangleMesh m = make_box(Vec3d(1, 1, 1));
    MeshTransform t;
    t.scale = Vec3d(2, 3, 4);
    t.rotation_deg = Vec3d(0, 0, 90);
    t.translation = Vec3d(10, 0, 0);
    apply_transform(m, t);
    CHECK(signed_volume(m) == doctest::Approx(24.0));
    const Aabb b = bounding_box(m);
    CHECK(b.center().x() == doctest::Approx(10.0));
    CHECK(b.extent().x() == doctest::Approx(3.0));  // y size 3 rotated onto x
    CHECK(b.extent().y() == doctest::Approx(2.0));
    TriangleMesh mirrored = make_box(Vec3d(1, 1, 1));
    MeshTransform mirror;
    mirror.scale = Vec3d(-1, 1, 1);
    apply_transform(mirrored, mirror);
    CHECK(signed_volume(mirrored) == doctest::Approx(1.0));
    MeshTransform zero;
    zero.scale = Vec3d(1, 0, 1);
    CHECK_THROWS_AS(apply_transform(mirrored, zero), InputError);
}

TEST_CASE("OBJ input: polygons are triangulated") {
    const std::string quad_cube =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    const TriangleMesh m = parse_obj(quad_cube, "cube.obj");
    CHECK(m.triangles.size() == 12);
    CHECK(signed_volume(m) == doctest::Approx(1.0));
    CHECK(edge_report(m).closed());
}

TEST_CASE("bad mesh input gives one clear error naming the file and the problem") {
    const std::string& tet_faces = mwtest::kTetFaces;
    CHECK(error_of([] { load_obj("/nonexistent/dir/missing.obj"); }) ==
          "/nonexistent/dir/missing.obj: mesh file does not exist");
    CHECK(error_of([] { load_obj(std::filesystem::temp_directory_path().string()); }).find("not a regular file") !=
          std::string::npos);
    CHECK(error_of([] { parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "points.obj"); }) == "points.obj: the mesh has no triangles");
    CHECK(error_of([] { parse_obj("", "empty.obj"); }) == "empty.obj: the mesh has no triangles");
    const std::string nan_err =
        error_of([&] { parse_obj("v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 0 1\n" + tet_faces, "nan.obj"); });
    CHECK(nan_err.rfind("nan.obj: vertex 3 is not finite", 0) == 0);
    const std::string flat = error_of([] { parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n", "flat.obj"); });
    CHECK(flat.rfind("flat.obj: the mesh encloses zero volume", 0) == 0);
    // A closed surface folded onto itself: two copies of a triangle with opposite windings.
    const std::string folded = error_of([] { parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 4\nf 1 4 2\n", "folded.obj"); });
    CHECK(folded.rfind("folded.obj: the mesh encloses zero volume", 0) == 0);
    // Out-of-range index: tinyobjloader rejects it or we do; either way the file is named.
    const std::string bad_index = error_of([] { parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "index.obj"); });
    CHECK(bad_index.rfind("index.obj: ", 0) == 0);
    // Via a real file as well (NaN written by a tool).
    const std::string path = (scratch_dir() / "nan.obj").string();
    {
        std::ofstream f(path);
        f << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 inf\n" << tet_faces;
    }
    CHECK(error_of([&] { load_obj(path); }).rfind(path + ": vertex 4 is not finite", 0) == 0);
}

TEST_CASE("malformed OBJ lines are named by their line, never misreported or dropped") {
    const std::string& tet_vertices = mwtest::kTetVertices;
    const std::string& tet_faces = mwtest::kTetFaces;
    auto error = [](const std::string& text) { return error_of([&] { parse_obj(text, "m.obj"); }); };
    // Too few coordinates: tinyobjloader would read the missing z as 0.
    CHECK(error("v 0 0 0\nv 1 0\nv 0 1 0\nv 0 0 1\n" + tet_faces) ==
          "m.obj: vertex 2 has 2 coordinates, a vertex needs x y z (line 2: 'v 1 0')");
    // A file cut off in the middle of a vertex line says so.
    const std::string truncated = error(tet_faces + tet_vertices + "v 1 2");
    CHECK(truncated.rfind("m.obj: vertex 5 has 2 coordinates, a vertex needs x y z (line 9: 'v 1 2')", 0) == 0);
    CHECK(truncated.find("truncated") != std::string::npos);
    CHECK(error("v 0 0 0\nv 1 0 0\nv 0 1,5 0\nv 0 0 1\n" + tet_faces) ==
          "m.obj: vertex 3: '1,5' is not a number (line 3: 'v 0 1,5 0')");
    CHECK(error("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e39\n" + tet_faces).rfind("m.obj: vertex 4: 1e39 is beyond", 0) == 0);
    // Faces with fewer than 3 corners are errors, not silently dropped.
    CHECK(error(tet_vertices + tet_faces + "f 1 3\n") == "m.obj: face 5 has 2 corners, a face needs at least 3 (line 9: 'f 1 3')");
    CHECK(error(tet_vertices + "f \n" + tet_faces).rfind("m.obj: face 1 has 0 corners", 0) == 0);
    // Indices are reported as written: tinyobjloader's atoi wraps 99999999999 to 1215752191.
    CHECK(error(tet_vertices + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 99999999999\n") ==
          "m.obj: face 4 refers to vertex 99999999999, but the file has 4 vertices (line 8: 'f 3 1 99999999999')");
    // A quad with a bad index: tinyobjloader would drop it with a warning.
    CHECK(error(tet_vertices + "f 1 2 3 9\n" + tet_faces) ==
          "m.obj: face 1 refers to vertex 9, but the file has 4 vertices (line 5: 'f 1 2 3 9')");
    CHECK(error(tet_vertices + "f 0 1 2\n").rfind("m.obj: face 1 refers to vertex 0, but OBJ vertex indices start at 1", 0) == 0);
    CHECK(error(tet_vertices + "f -1 -2 -5\n").rfind("m.obj: face 1 refers to vertex -5 (counted back from the end), but "
                                                     "only 4 vertices precede it", 0) == 0);
    CHECK(error(tet_vertices + "f 1 2 x\n").rfind("m.obj: face 1: 'x' is not a vertex index", 0) == 0);
    // Still accepted: relative indices, v/vt/vn corners, faces before the vertices they use.
    CHECK(parse_obj(tet_vertices + "f -4 -2 -3\nf -4 -3 -1\nf -3 -2 -1\nf -2 -4 -1\n", "rel.obj").triangles.size() == 4);
    CHECK(parse_obj(tet_vertices + "vt 0 0\nvn 0 0 1\nf 1/1/1 3/1/1 2/1/1\nf 1//1 2//1 4//1\nf 2/1 3/1 4/1\nf 3 1 4\n",
                    "vtvn.obj").triangles.size() == 4);
    CHECK(parse_obj(tet_faces + tet_vertices, "faces_first.obj").triangles.size() == 4);
}

TEST_CASE("OBJ numbers the reader would overflow on: exponents read as written, unused lines never read") {
    const std::string& tet_vertices = mwtest::kTetVertices;
    const std::string& tet_faces = mwtest::kTetFaces;
    const TriangleMesh plain = parse_obj(tet_vertices + tet_faces, "plain.obj");
    // Exponents beyond int: tinyobjloader's parser overflows on them (undefined behaviour, caught
    // by `make sanitize`) and reads 1e-2147483649 as infinity. Both are 0 here, as strtod reads them.
    const TriangleMesh tiny = parse_obj("v 0e2147483648 0 0\nv 1 0 0\nv 0 1 0\nv 1e-2147483649 0 1\n" + tet_faces, "e.obj");
    CHECK(tiny.vertices[0].x() == 0.0);
    CHECK(tiny.vertices[3].x() == 0.0);
    CHECK(tiny.vertices[3].z() == 1.0);
    // A coordinate written with a long exponent or many digits reads as the number it is.
    const TriangleMesh long_form = parse_obj(
        "v 0 0 0\nv 1000000000000000000000000000000000000000e-0000000000000000000000000039 0 0\nv 0 1.0e+0000 0\n"
        "v 0 0 0.100000000000000000000000000000000000000000000000000001e1\n" + tet_faces, "long.obj");
    for (std::size_t i = 0; i < plain.vertices.size(); ++i) CHECK(long_form.vertices[i] == plain.vertices[i]);
    // Lines the sampler does not use are not read at all: skin weights (which the reader converts
    // to int unchecked), vertex colours, normals and texture coordinates out of any range,
    // smoothing groups, tags, lines and points.
    const std::string unused =
        "vw 0 3e9 1\nvw 1 -1e300 1e300\nvn 1e999999999999 0 0\nvt 0e2147483648 1\ns 99999999999\n"
        "t crease 2/1/0 1 2\nl 1 99999999999\np 1\no name\ng a b\nusemtl none\nmtllib missing.mtl\n";
    const TriangleMesh with_unused =
        parse_obj(unused + "v 0 0 0 1e2147483648 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + tet_faces, "unused.obj");
    REQUIRE(with_unused.vertices.size() == plain.vertices.size());
    for (std::size_t i = 0; i < plain.vertices.size(); ++i) CHECK(with_unused.vertices[i] == plain.vertices[i]);
    CHECK(with_unused.triangles == plain.triangles);
    // Texture and normal indices in faces are not read either: only the vertex index counts.
    const TriangleMesh corners =
        parse_obj(tet_vertices + "f 1/99999999999/1 3/1/-99999999999 2//1\nf 1 2 4\nf 2 3 4\nf 3 1 4\n", "c.obj");
    CHECK(corners.triangles == plain.triangles);
}

TEST_CASE("coordinates out of range or too far to resolve: one clear error, the mesh left as it was") {
    TriangleMesh box = make_box(Vec3d(1, 1, 1));
    box.source = "box";
    const std::vector<Vec3d> before = box.vertices;
    MeshTransform huge;
    huge.scale = Vec3d(1e300, 1e300, 1e300);
    const std::string overflow = error_of([&] { apply_transform(box, huge); });
    CHECK(overflow.rfind("box: the transform (scale 1e+300,1e+300,1e+300, rotation 0,0,0, translation 0,0,0) takes "
                         "vertex 1 to (-5e+299, -5e+299, -5e+299), outside the range", 0) == 0);
    CHECK(box.vertices == before);
    MeshTransform far;
    far.translation = Vec3d(1e30, 0, 0);
    const std::string unresolved = error_of([&] { apply_transform(box, far); });
    CHECK(unresolved.find("too far for double precision to resolve it") != std::string::npos);
    CHECK(box.vertices == before);
    far.translation = Vec3d(1e8, 0, 0);  // 1e8 box sizes away: still resolved to 1e-8 of its size
    CHECK_NOTHROW(apply_transform(box, far));
    // The same limits for meshes read as they are.
    TriangleMesh big = make_box(Vec3d(1, 1, 1));
    big.source = "big.obj";
    big.vertices[0] = Vec3d(1e31, 0, 0);
    CHECK(error_of([&] { validate_mesh(big); }).rfind("big.obj: vertex 1 (1e+31, 0, 0) is out of range", 0) == 0);
    TriangleMesh distant = make_box(Vec3d(1, 1, 1));
    distant.source = "distant.obj";
    for (Vec3d& v : distant.vertices) v.x() += 1e12;
    CHECK(error_of([&] { validate_mesh(distant); }).rfind("distant.obj: the mesh (size 1.73205) lies 1e+12 from the origin", 0) ==
          0);
}

TEST_CASE("the shared meshes load with the expected topology") {
    if (mwtest::missing_mesh("spot.obj") || mwtest::missing_mesh("stanford-bunny.obj")) return;
    const TriangleMesh spot = load_obj(mwtest::mesh_dir() + "/spot.obj");
    CHECK(spot.triangles.size() == 5856);
    CHECK(edge_report(spot).closed());
    const TriangleMesh bunny = load_obj(mwtest::mesh_dir() + "/stanford-bunny.obj");
    CHECK(bunny.triangles.size() == 69451);
    CHECK(edge_report(bunny).boundary_edges == 223);
    CHECK(signed_volume(bunny) == doctest::Approx(7.70e-4).epsilon(0.01));
}

TEST_CASE("OBJ edges: line elements read as an outline's edges, and what is not one is refused naming the file") {
    const auto write = [](const std::string& name, const std::string& text) {
        const std::string path = (scratch_dir() / name).string();
        std::ofstream(path) << text;
        return path;
    };
    // Two "l a b" edges and one line of three points: four edges, each (a, b, a).
    const mw::TriangleMesh m = mw::load_obj_edges(write("edges.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nl 1 2\nl 2 3\nl 3 4 1\n"));
    REQUIRE(m.vertices.size() == 4);
    REQUIRE(m.triangles.size() == 4);
    CHECK(m.triangles[2] == std::array<int, 3>{2, 3, 2});
    CHECK(m.triangles[3] == std::array<int, 3>{3, 0, 3});
    CHECK(mw::load_obj_edges(write("empty.obj", "# no fluid\n")).triangles.empty());
    for (const auto& refused : {std::tuple<std::string, std::string, std::string>{"faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "holds faces"},
                                 {"past.obj", "v 0 0 0\nv 1 0 0\nl 1 5\n", "past the 2"}}) {
        // Named copies: CAPTURE's lambda cannot capture a structured binding under clang 14.
        const std::string name = std::get<0>(refused), part = std::get<2>(refused);
        CAPTURE(name);
        const std::string path = write(name, std::get<1>(refused));
        try {
            mw::load_obj_edges(path);
            FAIL("accepted");
        } catch (const mw::InputError& e) {
            CHECK(std::string(e.what()).find(path) != std::string::npos);
            CHECK(std::string(e.what()).find(part) != std::string::npos);
        }
    }
    CHECK_THROWS_AS(mw::load_obj_edges((scratch_dir() / "missing.obj").string()), mw::InputError);
}
