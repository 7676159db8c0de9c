// 2D scenes from the command line: `dimensions: 2` runs fluid in the plane z = 0 (the physics is
// checked in tests/core: test_hydrostatic.cpp, test_dam_break.cpp, test_two_dimensions.cpp), its
// frames hold z = 0 and
// its pictures look at the plane head-on; what 2D scenes cannot hold yet is refused in one line.
#include <doctest/doctest.h>

#include <filesystem>
#include <sstream>

#include "apps/vtu_reader.hpp"
#include "cli_helpers.hpp"
#include "pictures.hpp"

using namespace cli_test;
namespace fs = std::filesystem;

namespace {
// A 2D dam break 0.4 x 0.3 m: a 0.1 x 0.2 m column (10 x 20 particles), with `extra` spliced in.
std::string tiny_2d_text(const std::string& extra = "") {
    return std::string(R"({
  "name": "tiny_2d",
  "dimensions": 2,
  "domain": { "min": [0, 0], "max": [0.4, 0.3] },
  "fluid": { "spacing": 0.01 },
  "solver": { "dt": 0.002, "dt_mode": "cfl" },
  "fluid_blocks": [ { "min": [0, 0], "max": [0.1, 0.2] } ])") +
           (extra.empty() ? "" : ",\n  " + extra) + "\n}\n";
}
}  // namespace

TEST_CASE("2D scene: the frames hold the plane z = 0 and the picture looks at it head-on") {
    const std::string scene = scene_file("tiny_2d.json", tiny_2d_text());
    const std::string dir = out_dir("tiny_2d_run");
    const Result r = run("run " + scene + " --time 0.1 --quiet --checkpoint --out " + dir +
                         " --set output.fps=10 --set 'output.formats=[\"vtu\",\"preview\"]'");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    const auto summary = read_json(dir + "/summary.json");
    CHECK(summary["particles"]["fluid"] == 200);
    CHECK(summary["lost_particles"] == 0);
    CHECK(summary["scene"]["dimensions"] == 2);
    const mw::VtuFrame frame = mw::read_vtu(dir + "/frames/particles_00001.vtu");
    REQUIRE(frame.points.size() == 200);
    double largest_z = 0, lowest_top = 1;
    for (const mw::Vec3& x : frame.points) largest_z = std::max(largest_z, std::fabs(double(x.z)));
    for (const mw::Vec3& x : frame.points) lowest_top = std::min(lowest_top, double(x.y));
    CHECK(largest_z == 0);
    CHECK(lowest_top > 0);  // above the floor's layer
    CHECK(fs::exists(dir + "/frames/preview_00001.png"));
    // Head-on: the camera stands in front of the domain's middle height, a little right of its
    // middle so that the domain sits left of the legend.
    const auto eye = summary["scene"]["output"]["preview"]["eye"];
    CHECK(eye[0].get<double>() > 0.2);
    CHECK(eye[0].get<double>() < 0.3);
    CHECK(eye[1].get<double>() == doctest::Approx(0.15));
    CHECK(eye[2].get<double>() > 0.3);
    // The resolved scene (camera off the plane included) reads back: a 2D run resumes.
    const Result resumed = run("run --resume " + dir + "/checkpoint.mwc --time 0.14 --quiet");
    CAPTURE(resumed.err);
    CHECK(resumed.code == 0);
}

TEST_CASE("2D scene: surface frames are the fluid's contour, as OBJ and PLY edges, drawn and drawn again") {
    // With a rigid rectangle falling beside the column: its outline's OBJ frames are line
    // elements too, which render reads back and leaves to the particles, as the run's preview does.
    const std::string scene = scene_file("tiny_2d_surface.json", tiny_2d_text(R"("objects": [{ "kind": "rigid", "density": 500, "mesh": { "procedural": "rectangle:x=0.06,y=0.04" }, "transform": { "translation": [0.3, 0.1] } }])"));
    const std::string dir = out_dir("tiny_2d_surface");
    const Result r = run("run " + scene + " --time 0.1 --quiet --out " + dir +
                         " --set output.fps=10 --set 'output.formats=[\"vtu\",\"ply\",\"surface\",\"preview\"]'");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    for (const char* frame : {"00000", "00001"}) {
        CAPTURE(frame);
        const std::string obj = slurp(dir + "/frames/surface_" + frame + ".obj");
        long vertices = 0, edges = 0, faces = 0;
        std::istringstream lines(obj);
        for (std::string line; std::getline(lines, line);) {
            vertices += line.rfind("v ", 0) == 0;
            edges += line.rfind("l ", 0) == 0;
            faces += line.rfind("f ", 0) == 0;
            if (line.rfind("v ", 0) == 0) CHECK(line.substr(line.rfind(' ')) == " 0");  // z = 0
        }
        // One closed loop round the column: as many edges as vertices, about one a voxel (r0/2)
        // round a 0.1 x 0.2 m column (120 voxels).
        CHECK(faces == 0);
        CHECK(edges == vertices);
        CHECK(edges > 80);
        CHECK(edges < 200);
        CHECK(contains(slurp(dir + "/frames/surface_" + frame + ".ply"), "element edge " + std::to_string(edges)));
    }
    // The picture draws the contour (a dark blue band, lit head-on: 15, 53, 128); render reads it
    // back from the OBJ and draws the same picture.
    const Result again = run("render " + dir + " --out " + dir + "/again");
    CAPTURE(again.err);
    REQUIRE(again.code == 0);
    const Pixels drawn = png_pixels(dir + "/frames/preview_00001.png"), redrawn = png_pixels(dir + "/again/preview_00001.png");
    REQUIRE(redrawn.size() == drawn.size());
    CHECK(differing_pixels(drawn, redrawn) < drawn.size() / 3 / 1000);
    long line_pixels = 0;
    for (std::size_t k = 0; k + 2 < drawn.size(); k += 3)
        line_pixels += drawn[k] < 30 && drawn[k + 1] > 40 && drawn[k + 1] < 70 && drawn[k + 2] > 110;
    CHECK(line_pixels > 100);
}

TEST_CASE("2D scene: what it cannot hold yet, and points off the plane, are refused in one line") {
    struct Case {
        const char* name;
        std::string extra;
        std::vector<std::string> parts;
    };
    const std::vector<Case> cases = {
        {"cloth", R"("objects": [{ "kind": "cloth", "mesh": { "procedural": "rectangle:x=0.05,y=0.05" }, "transform": { "translation": [0.3, 0.1] } }])",
         {"objects[0].kind", "elastic, rigid, static or rod"}},
        {"object turned out of the plane", R"("objects": [{ "mesh": { "procedural": "rectangle:x=0.05,y=0.05" }, "transform": { "translation": [0.3, 0.1], "rotation_deg": [10, 0, 0] } }])",
         {"objects[0].transform.rotation_deg", "[0, 0, angle]"}},
        {"object off the plane", R"("objects": [{ "mesh": { "procedural": "rectangle:x=0.05,y=0.05" }, "transform": { "translation": [0.3, 0.1, 0.2] } }])",
         {"objects[0].transform.translation", "plane z = 0"}},
        {"a 3D mesh in 2D", R"("objects": [{ "mesh": { "procedural": "box:x=0.05,y=0.05,z=0.05" }, "transform": { "translation": [0.3, 0.1] } }])",
         {"objects[0]", "unknown procedural outline 'box'", "rectangle"}},
        {"a rigid object melting in 2D", R"("heat": { "enabled": true }, "objects": [{ "kind": "rigid", "mesh": { "procedural": "rectangle:x=0.05,y=0.05" }, "transform": { "translation": [0.3, 0.1] }, "melting_point": 0 }])",
         {"objects[0].melting_point", "elastic objects"}},
        {"surface spacing of a rod", R"("objects": [{ "kind": "rod", "mesh": { "procedural": "line:length=0.1" }, "transform": { "translation": [0.3, 0.1] }, "surface_spacing": 0.5 }])",
         {"objects[0].surface_spacing", "elastic and rigid objects"}},
        {"an OBJ file in 2D", R"("objects": [{ "mesh": { "file": "missing.obj" }, "transform": { "translation": [0.3, 0.1] } }])",
         {"objects[0]", "missing.obj"}},
        {"static box off the plane", R"("static_boxes": [{ "min": [0.2, 0, 0], "max": [0.3, 0.1, 0.1] }])",
         {"static_boxes[0].max", "plane z = 0"}},
        {"emitter off the plane", R"("emitters": [{ "center": [0.2, 0.25, 0.1], "direction": [0, -1, 0], "radius": 0.02, "speed": 1 }])",
         {"emitters[0].center", "plane z = 0"}},
        {"a pressure sensor off the sides", R"("pressure_sensors": [{ "center": [0.2, 0.15] }])",
         {"pressure_sensors[0].center", "face of the domain"}},
        {"vdb frames", R"("output": { "formats": ["vdb"] })", {"output.formats", "3D output"}},
        {"gravity off the plane", R"("gravity": [0, -9.81, 1])", {"gravity", "plane z = 0"}},
        {"vector of 4", R"("gravity": [0, -9.81, 0, 0])", {"gravity", "2 numbers [x, y]"}},
    };
    for (const Case& c : cases) {
        const std::string name = c.name;
        CAPTURE(name);
        check_rejected(run("info " + scene_file("refused_2d.json", tiny_2d_text(c.extra))), c.parts);
    }
}
