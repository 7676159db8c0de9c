// The scene parser in-process: defaults, resolution, overrides and every kind of bad input.
#define DOCTEST_CONFIG_IMPLEMENT
#include "tests/skip.hpp"

#include <filesystem>

#include "apps/cli_common.hpp"
#include "apps/scene.hpp"
#include "apps/scene_builder.hpp"
#include "common/errors.hpp"
#include "cli_helpers.hpp"

using namespace mw;
using cli_test::contains;
using cli_test::tiny_scene_text;

namespace {
// The one-line message of the InputError that parsing `text` with `overrides` throws ("" if none).
std::string parse_error(const std::string& text, const std::vector<std::string>& overrides = {}) {
    try {
        parse_scene_text(text, "test.json", overrides);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}
}  // namespace

TEST_CASE("the built-in default scene resolves to a ~50k particle dam break") {
    const Scene s = load_scene("");
    CHECK(s.name == "dam_break");
    CHECK(s.source == "built-in default scene");
    const SimulationSetup setup = build_setup(s);
    const ParticleCounts c = count_particles(setup);
    CHECK(c.by_type[kFluid] >= 40000);
    CHECK(c.by_type[kFluid] <= 60000);
    CHECK(c.by_type[kStaticBoundary] > 0);
    CHECK(setup.position.size() == setup.velocity.size());
    CHECK(setup.position.size() == setup.type.size());
    CHECK(setup.position.size() == setup.object.size());
}

TEST_CASE("the shipped scenes resolve and build") {
    const bool shared_meshes = std::filesystem::exists(std::string(MW_SHARED_DIR) + "/assets/meshes");
    int scenes = 0, built = 0;
    for (const auto& entry : std::filesystem::directory_iterator(std::string(MW_SOURCE_DIR) + "/scenes")) {
        if (entry.path().extension() != ".json") continue;
        const std::string name = entry.path().filename().string();
        CAPTURE(name);
        ++scenes;
        const Scene s = load_scene(entry.path().string());
        CHECK(!s.name.empty());
        // A scene whose mesh lives in ../shared is built only where that folder is. load_scene has
        // already made mesh paths absolute (from the scene file's folder): the files build_setup reads.
        bool meshes_present = true;
        for (const SceneObject& o : s.objects)
            meshes_present = meshes_present && (o.mesh_file.empty() || std::filesystem::exists(o.mesh_file));
        if (!meshes_present) {
            // Only the shared meshes may be absent, and only with their folder.
            CHECK(!shared_meshes);
            MESSAGE(name << ": its mesh is absent (the shared meshes live in ../shared/assets/meshes), not built");
            continue;
        }
        const ParticleCounts c = count_particles(build_setup(s));
        CHECK(c.total() > 0);
        CHECK(c.by_type[kFluid] + c.by_type[kInnerBoundary] > 0);  // something moves
        ++built;
    }
    // Every scene was built, or skipped for the shared folder's absence (checked above).
    CHECK(scenes >= 6);
    if (shared_meshes) CHECK(built == scenes);
    const Scene block = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/splishsplash_block.json");
    CHECK(count_particles(build_setup(block)).by_type[kFluid] == 6859);
}

TEST_CASE("defaults are filled in and recorded in the resolved scene") {
    const Scene s = parse_scene_text(tiny_scene_text(), "t");
    CHECK(s.params.fluid.rest_density == doctest::Approx(1000));
    CHECK(s.params.fluid.support_radius == doctest::Approx(0.04));
    CHECK(s.params.fluid.kernel == KernelKind::kCubicSpline);
    CHECK(s.params.fluid.viscosity == 0);
    CHECK(s.params.gravity.y == doctest::Approx(-9.81));
    CHECK(s.params.solver.dt_mode == TimeStepMode::kFixed);
    CHECK(s.params.solver.eta == doctest::Approx(0.01));
    CHECK(s.params.solver.eta_max == doctest::Approx(0.05));  // 5 eta
    CHECK(s.params.solver.min_iterations == 3);
    CHECK(s.params.solver.max_iterations == 100);
    CHECK(s.params.solver.shorten_above_iterations == 6);  // 2 min_iterations
    CHECK(s.params.neighbors.ordering == CellOrdering::kZOrder);
    CHECK(s.boundary_spacing_factor == doctest::Approx(0.5));
    CHECK(s.boundary_layers == 1);
    CHECK(s.end_time == doctest::Approx(1.0));
    CHECK(s.fps == doctest::Approx(30));
    REQUIRE(s.formats.size() == 1);
    CHECK(s.formats[0] == "vtu");
    const SceneJson& r = s.resolved;
    CHECK(r["dimensions"] == 3);
    CHECK(r["fluid"]["support_radius"].get<double>() == doctest::Approx(0.04));
    CHECK(r["gravity"][1].get<double>() == doctest::Approx(-9.81));
    CHECK(r["solver"]["dt_mode"] == "fixed");
    CHECK(r["fluid"]["kernel"] == "cubic_spline");
    CHECK(r["solver"]["eta_max"].get<double>() == 0.05);  // computed in double: no float residue
    CHECK(r["neighbors"]["ordering"] == "zorder");
    CHECK(r["fluid_blocks"][0]["velocity"].size() == 3);
    CHECK(r["run"]["end_time"].get<double>() == doctest::Approx(1.0));
    CHECK(r["output"]["formats"][0] == "vtu");
    CHECK(r["static_boxes"].is_array());
    // Resolving the resolved scene gives the same scene.
    CHECK(resolve_scene(r, "again").resolved == r);
}

TEST_CASE("--set overrides reach every kind of key") {
    const Scene s = parse_scene_text(tiny_scene_text(), "t",
                                     {"solver.eta=0.005", "solver.dt_mode=cfl", "gravity=[0,-1,0]",
                                      "fluid_blocks.0.velocity=[1,0,0]", "fluid_blocks[0].max=[0.1,0.12,0.1]",
                                      "output.formats=[]", "name=renamed", "neighbors.ordering=\"linear\"",
                                      "static_boxes=[{\"min\":[0.15,0,0.15],\"max\":[0.2,0.05,0.2]}]",
                                      "static_boxes.0.layers=2", "fluid.kernel=wendland_c2"});
    CHECK(s.params.fluid.kernel == KernelKind::kWendlandC2);
    CHECK(s.params.solver.eta == doctest::Approx(0.005));
    CHECK(s.params.solver.dt_mode == TimeStepMode::kCfl);
    CHECK(s.params.gravity.y == doctest::Approx(-1));
    CHECK(s.fluid_blocks[0].velocity.x == doctest::Approx(1));
    CHECK(s.fluid_blocks[0].max.y == doctest::Approx(0.12));
    CHECK(s.formats.empty());
    CHECK(s.name == "renamed");
    CHECK(s.params.neighbors.ordering == CellOrdering::kLinear);
    REQUIRE(s.static_boxes.size() == 1);
    CHECK(s.static_boxes[0].layers == 2);
    CHECK(s.resolved["solver"]["eta"].get<double>() == doctest::Approx(0.005));
    // A derived default follows its base when not given explicitly.
    const Scene t = parse_scene_text(tiny_scene_text(), "t", {"fluid.spacing=0.01"});
    CHECK(t.params.fluid.support_radius == doctest::Approx(0.02));
    // So does the peak bound: 5 eta, and off where that would be 1 or more; 0 turns it off.
    CHECK(s.params.solver.eta_max == doctest::Approx(0.025));
    CHECK(parse_scene_text(tiny_scene_text(), "t", {"solver.eta=0.3"}).params.solver.eta_max == 0);
    CHECK(parse_scene_text(tiny_scene_text(), "t", {"solver.eta_max=0"}).params.solver.eta_max == 0);
    CHECK(parse_scene_text(tiny_scene_text(), "t", {"solver.eta=0.002", "solver.eta_max=0.03"}).params.solver.eta_max ==
          doctest::Approx(0.03));
}

TEST_CASE("--set overrides that depend on each other are checked together, in any order") {
    // Spacing alone would leave the old support radius out of its range, and the other way round.
    // (The first override makes the support radius explicit, so it no longer follows the spacing.)
    for (const auto& overrides :
         {std::vector<std::string>{"fluid.support_radius=0.04", "fluid.spacing=0.005", "fluid.support_radius=0.01"},
          std::vector<std::string>{"fluid.support_radius=0.01", "fluid.spacing=0.005"}}) {
        const Scene s = parse_scene_text(tiny_scene_text(), "t", overrides);
        CHECK(s.params.fluid.spacing == doctest::Approx(0.005));
        CHECK(s.params.fluid.support_radius == doctest::Approx(0.01));
    }
    // A combination that stays invalid is reported once, naming the key and the overrides.
    const std::string message = parse_error(tiny_scene_text(), {"fluid.spacing=0.005", "fluid.support_radius=0.5"});
    CHECK(contains(message, "fluid.support_radius"));
    CHECK(contains(message, "--set fluid.spacing=0.005, --set fluid.support_radius=0.5"));
}

TEST_CASE("bad scenes give one line naming the key") {
    struct Case {
        const char* what;
        std::string text;
        std::vector<std::string> overrides;
        std::vector<std::string> expect;  // every part must be in the message
    };
    const std::string tiny = tiny_scene_text();
    const std::vector<Case> cases = {
        {"malformed JSON", "{ \"domain\": ", {}, {"test.json", "malformed JSON", "line"}},
        {"not an object", "[1, 2]", {}, {"test.json", "JSON object"}},
        {"unknown top-level key", tiny_scene_text("\"fluids\": {}"), {}, {"fluids", "unknown key"}},
        {"unknown nested key", tiny_scene_text("\"output\": {\"fsp\": 3}"), {}, {"output.fsp", "unknown key"}},
        {"unknown key in an array element", tiny, {"fluid_blocks=[{\"min\":[0,0,0],\"max\":[0.1,0.1,0.1],\"vel\":[0,0,0]}]"},
         {"fluid_blocks[0].vel", "unknown key"}},
        {"missing domain", "{\"fluid\": {\"spacing\": 0.02}}", {}, {"domain.min", "required"}},
        {"missing spacing", tiny, {"fluid={}"}, {"fluid.spacing", "required"}},
        {"wrong type (string for number)", tiny, {"solver.dt=abc"}, {"solver.dt", "expected a number"}},
        {"wrong type (number for section)", tiny, {"solver=3"}, {"solver", "expected an object"}},
        {"wrong type (vector)", tiny, {"gravity=[0,1]"}, {"gravity", "3 numbers"}},
        {"wrong type (bool)", tiny, {"boundary.walls=3"}, {"boundary.walls", "true or false"}},
        {"eta out of range", tiny, {"solver.eta=1.5"}, {"solver.eta", "(0, 1)", "1.5"}},
        {"negative viscosity", tiny, {"fluid.viscosity=-1"}, {"fluid.viscosity", ">= 0"}},
        {"negative solid substep", tiny, {"solver.solid_substep=-0.001"}, {"solver.solid_substep", "[0, 1]", "-0.001"}},
        {"support radius too small", tiny, {"fluid.support_radius=0.01"}, {"fluid.support_radius", "(0.02, 0.08]"}},
        {"support radius too large", tiny, {"fluid.support_radius=0.2"}, {"fluid.support_radius"}},
        {"non-integer", tiny, {"boundary.layers=1.5"}, {"boundary.layers", "integer"}},
        {"layers out of range", tiny, {"boundary.layers=9"}, {"boundary.layers", "[1, 8]"}},
        {"iterations inverted", tiny, {"solver.max_iterations=2"}, {"solver.max_iterations", "min_iterations"}},
        {"shortening below the least iterations", tiny, {"solver.shorten_above_iterations=2"},
         {"solver.shorten_above_iterations", "0 (off) or >= min_iterations (3)", "got 2"}},
        {"bad choice", tiny, {"solver.dt_mode=adaptive"}, {"solver.dt_mode", "fixed, cfl", "adaptive"}},
        {"unknown kernel", tiny, {"fluid.kernel=quintic"}, {"fluid.kernel", "cubic_spline, wendland_c2", "quintic"}},
        {"bad format", tiny, {"output.formats=[\"obj\"]"}, {"output.formats[0]", "vtu"}},
        {"dimensions neither 2 nor 3", tiny, {"dimensions=4"}, {"dimensions", "expected 2 or 3", "4"}},
        {"3D domain in a 2D scene", tiny, {"dimensions=2"}, {"domain.max", "plane z = 0"}},
        {"2D vector of 2 in a 3D scene", tiny, {"domain.max=[1,1]"}, {"domain.max", "3 numbers"}},
        {"inverted domain", tiny, {"domain.max=[0.2,-1,0.2]"}, {"domain.max", "exceed min"}},
        {"block outside the domain", tiny, {"fluid_blocks.0.max=[0.1,0.5,0.1]"}, {"fluid_blocks[0]", "inside the domain"}},
        {"no fluid", tiny, {"fluid_blocks=[]"}, {"fluid_blocks", "at least one"}},
        {"zero fps", tiny, {"output.fps=0"}, {"output.fps"}},
        {"--set unknown key", tiny, {"solver.etaa=0.1"}, {"--set solver.etaa", "no such key"}},
        {"--set unknown section", tiny, {"solvers.eta=0.1"}, {"--set solvers.eta", "no such key"}},
        {"--set bad index", tiny, {"fluid_blocks.3.min=[0,0,0]"}, {"fluid_blocks", "index"}},
        {"--set without =", tiny, {"solver.eta"}, {"--set solver.eta", "KEY=VALUE"}},
        {"--set into a value", tiny, {"solver.eta.x=1"}, {"--set solver.eta.x"}},
        {"--set stray bracket", tiny, {"fluid_blocks[0]].min=[0,0,0]"}, {"malformed key path"}},
        {"--set non-index bracket", tiny, {"fluid_blocks[x].min=[0,0,0]"}, {"malformed key path", "[N]"}},
        // A misspelt key: the missing key is named, and so is the key that is probably it.
        {"misspelt section", "{\"domian\": {\"min\": [0,0,0], \"max\": [1,1,1]}, \"fluid\": {\"spacing\": 0.02}}", {},
         {"domain.min", "required", "\"domian\""}},
        {"misspelt key", tiny, {"fluid={\"spaceing\": 0.02}"}, {"fluid.spacing", "\"spaceing\""}},
        {"misspelt array",
         "{\"domain\": {\"min\": [0,0,0], \"max\": [1,1,1]}, \"fluid\": {\"spacing\": 0.02}, \"fluid_block\": []}", {},
         {"fluid_blocks", "at least one", "\"fluid_block\""}},
        {"duplicate key", "{\"domain\": {\"min\": [0,0,0], \"max\": [1,1,1]}, \"fluid\": {\"spacing\": 0.02, \"spacing\": -1}}",
         {}, {"test.json", "fluid.spacing", "twice"}},
        {"duplicate key in an array element", tiny_scene_text("\"static_boxes\": [{\"min\": [0.1,0,0], \"min\": [0,0,0], \"max\": [0.2,0.1,0.1]}]"),
         {}, {"static_boxes[].min", "twice"}},
        {"overlapping fluid blocks", tiny, {"fluid_blocks=[{\"min\":[0,0,0],\"max\":[0.1,0.1,0.1]},{\"min\":[0.05,0,0],\"max\":[0.15,0.1,0.1]}]"},
         {"fluid_blocks[1]", "overlaps fluid_blocks[0]"}},
        {"a name that is a path", tiny, {"name=../../elsewhere"}, {"name", "letters, digits"}},
        {"duplicate key in a --set value", tiny, {"fluid={\"spacing\":0.04,\"spacing\":0.05}"}, {"--set fluid", "twice"}},
        {"text that is not UTF-8", tiny, {"description=caf\xe9"}, {"description", "UTF-8"}},
        {"a NUL in a key stays in the message", tiny_scene_text(R"("output": {"f\u0000ps": 3})"), {},
         {"output.f\\x00ps", "unknown key"}},
        {"misspelt mesh key", tiny_scene_text(R"("objects": [{"mesh": {"fiel": "x.obj"}}])"), {},
         {"objects[0].mesh", "\"fiel\""}},
        {"negative interface tension",
         tiny_scene_text(R"("objects": [{"mesh": {"procedural": "sphere:radius=0.03"}, "interface_tension": -1}])"), {},
         {"objects[0].interface_tension", "-1"}},
        {"negative body damping",
         tiny_scene_text(R"("objects": [{"mesh": {"procedural": "sphere:radius=0.03"}, "lsm": {"body_damping": -1}}])"), {},
         {"objects[0].lsm.body_damping", "-1"}},
        {"interface tension on a static object",
         tiny_scene_text(R"("objects": [{"mesh": {"procedural": "sphere:radius=0.03"}, "kind": "static", "interface_tension": 0.2}])"),
         {}, {"objects[0].interface_tension", "elastic, rigid and cloth", "static"}},
        {"a pressure sensor off the walls", tiny_scene_text(R"("pressure_sensors": [{"center": [0.1, 0.05, 0.1]}])"), {},
         {"pressure_sensors[0].center", "face of the domain", "0.05"}},
        {"a pressure sensor past its face", tiny_scene_text(R"("pressure_sensors": [{"center": [0.2, 0.01, 0.1], "size": 0.04}])"),
         {}, {"pressure_sensors[0].size", "reaches past"}},
        {"a pressure sensor of no size", tiny_scene_text(R"("pressure_sensors": [{"center": [0.2, 0.05, 0.1], "size": 0}])"), {},
         {"pressure_sensors[0].size", "> 0"}},
        {"two pressure sensors of one name",
         tiny_scene_text(R"("pressure_sensors": [{"name": "p", "center": [0.2, 0.05, 0.1]}, {"name": "p", "center": [0, 0.05, 0.1]}])"),
         {}, {"pressure_sensors[1].name", "two pressure sensors"}},
        {"a pressure sensor's unknown key", tiny_scene_text(R"("pressure_sensors": [{"center": [0.2, 0.05, 0.1], "diameter": 0.01}])"),
         {}, {"pressure_sensors[0].diameter", "unknown key"}},
        {"a cloth with heat conduction",
         tiny_scene_text(R"("heat": {"enabled": true}, "objects": [{"mesh": {"procedural": "sheet:x=0.1,z=0.1"}, "kind": "cloth"}])"),
         {}, {"objects[0].kind", "cloth does not conduct heat"}},
        {"pins given two ways",
         tiny_scene_text(R"("objects": [{"mesh": {"procedural": "sphere:radius=0.03"}, "pinned": {"box": {"min": [0, 0, 0], "max": [0.1, 0.1, 0.1]}, "boxes": []}}])"),
         {}, {"objects[0].pinned", "give one of"}},
        {"no pin boxes", tiny_scene_text(R"("objects": [{"mesh": {"procedural": "sphere:radius=0.03"}, "pinned": {"boxes": []}}])"),
         {}, {"objects[0].pinned.boxes", "at least one box"}},
        {"a pin box's unknown key",
         tiny_scene_text(R"("objects": [{"mesh": {"procedural": "sphere:radius=0.03"}, "pinned": {"boxes": [{"min": [0, 0, 0], "max": [0.1, 0.1, 0.1], "size": 1}]}}])"),
         {}, {"objects[0].pinned.boxes[0].size", "unknown key"}},
    };
    for (const Case& c : cases) {
        CAPTURE(c.what);
        const std::string message = parse_error(c.text, c.overrides);
        CAPTURE(message);
        CHECK(!message.empty());
        CHECK(message.find('\n') == std::string::npos);
        for (const auto& part : c.expect) CHECK(contains(message, part));
    }
}

TEST_CASE("arrays of blocks, boxes and objects are capped") {
    std::string blocks;
    for (int i = 0; i < 10001; ++i) blocks += std::string(i ? "," : "") + R"({"min":[0,0,0],"max":[0.1,0.1,0.1]})";
    const std::string message = parse_error(tiny_scene_text(), {"fluid_blocks=[" + blocks + "]"});
    CHECK(contains(message, "at most 10000"));
    std::string sensors;
    for (int i = 0; i < 65; ++i) sensors += std::string(i ? "," : "") + R"({"center":[0.2,0.05,0.1]})";
    const std::string too_many = parse_error(tiny_scene_text(), {"pressure_sensors=[" + sensors + "]"});
    CHECK(contains(too_many, "pressure_sensors[64]"));
    CHECK(contains(too_many, "at most 64"));
}

TEST_CASE("touching fluid blocks and a box beside the fluid are accepted") {
    CHECK(parse_error(tiny_scene_text(), {"fluid_blocks=[{\"min\":[0,0,0],\"max\":[0.1,0.1,0.1]},"
                                          "{\"min\":[0.1,0,0],\"max\":[0.2,0.1,0.1]}]",
                                          "static_boxes=[{\"min\":[0,0,0.1],\"max\":[0.1,0.05,0.2]}]"}) == "");
}

TEST_CASE("static boxes and objects carve the fluid: none is left inside them or closer than r0") {
    const Scene s = parse_scene_text(tiny_scene_text(R"("static_boxes": [{"min": [0.03, 0, 0.03], "max": [0.07, 0.05, 0.07]}],
        "objects": [{"mesh": {"procedural": "sphere:radius=0.025"}, "transform": {"translation": [0.05, 0.08, 0.05]}}])"),
                                     "t");
    long carved = 0;
    const SimulationSetup setup = build_setup(s, &carved);
    std::vector<Vec3> solid, fluid;
    for (std::size_t i = 0; i < setup.position.size(); ++i) {
        if (setup.type[i] == kFluid) fluid.push_back(setup.position[i]);
        if ((setup.type[i] == kStaticBoundary && setup.object[i] >= 0) || setup.type[i] == kSurfaceBoundary ||
            setup.type[i] == kInnerBoundary)
            solid.push_back(setup.position[i]);
    }
    CHECK(long(fluid.size()) + carved == 125);
    CHECK(carved > 8);  // at least the box's own 2 x 2 x 2 lattice points
    const Real r0 = s.params.fluid.spacing;
    double nearest = 1e9;
    long inside_box = 0;
    for (const Vec3& f : fluid) {
        for (const Vec3& b : solid) nearest = std::min(nearest, double(norm(f - b)));
        inside_box += f.x > 0.03f && f.x < 0.07f && f.y < 0.05f && f.z > 0.03f && f.z < 0.07f;
    }
    CHECK(inside_box == 0);
    CHECK(nearest >= kFluidClearance * r0 * (1 - 1e-4));  // exactly r0 stays, up to rounding
    // The solids' particle lists still name their own particles after the fluid was compacted.
    REQUIRE(setup.solids.size() == 2);  // the object, then the static box (a body with no particle lists)
    const SolidSetup& sphere = setup.solids[0];
    REQUIRE(!sphere.ibp.empty());
    for (std::uint32_t i : sphere.ibp) CHECK(setup.type[i] == kInnerBoundary);
    for (std::uint32_t i : sphere.sbp) CHECK(setup.type[i] == kSurfaceBoundary);
    for (std::uint32_t i : sphere.gp) CHECK(setup.type[i] == kGeometry);
    // A block that the solids fill completely is refused, naming it.
    const Scene filled = parse_scene_text(
        tiny_scene_text(R"("static_boxes": [{"min": [0, 0, 0], "max": [0.12, 0.12, 0.12]}])"), "t");
    try {
        build_setup(filled);
        FAIL_CHECK("a block inside a static box was accepted");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()).find("fluid_blocks[0]") != std::string::npos);
        CHECK(std::string(e.what()).find("no fluid particle is left") != std::string::npos);
    }
}

TEST_CASE("a static object gets a signed distance grid for the correction only where the correction can act") {
    const std::string object =
        R"("objects": [{"mesh": {"procedural": "sphere:radius=0.03"}, "transform": {"translation": [0.15, 0.1, 0.1]},
                        "kind": "static"}])";
    const SimulationSetup on = build_setup(parse_scene_text(tiny_scene_text(object), "t", {"boundary.correction=true"}));
    REQUIRE(on.params.boundary.static_objects.size() == 1);
    const ContactField& c = on.params.boundary.static_objects[0];
    const Real r0 = 0.02f;
    CHECK(c.contact == doctest::Approx(kStaticObjectContact * r0));
    CHECK(c.field.first == 0);
    CHECK(on.params.boundary.static_object_distances.size() == std::size_t(c.field.nx) * c.field.ny * c.field.nz);
    CHECK(1 / c.field.inv_spacing == doctest::Approx(r0 / 2));
    // The grid reaches past the band and one more cell beyond the sphere on every side.
    CHECK(c.field.origin.x <= 0.15f - 0.03f - c.contact - r0 / 2);
    CHECK(c.field.origin.x + (c.field.nx - 1) / c.field.inv_spacing >= 0.15f + 0.03f + c.contact + r0 / 2);
    // Negative at the centre, about the radius deep.
    Real d = 0;
    Vec3 g{0, 0, 0};
    REQUIRE(c.field.sample(View<const Real>{on.params.boundary.static_object_distances.data(),
                                            on.params.boundary.static_object_distances.size()},
                           Vec3{0.15f, 0.1f, 0.1f}, d, g));
    CHECK(std::abs(d + 0.03f) < 0.0015f);  // the icosphere's facets lie a little inside the sphere
    // Two objects: the second grid's values follow the first's.
    const std::string two =
        R"("objects": [{"mesh": {"procedural": "sphere:radius=0.03"}, "transform": {"translation": [0.15, 0.1, 0.1]},
                        "kind": "static"},
                       {"mesh": {"procedural": "box:x=0.04,y=0.04,z=0.04"}, "transform": {"translation": [0.15, 0.15, 0.15]},
                        "kind": "static"}])";
    const SimulationSetup both = build_setup(parse_scene_text(tiny_scene_text(two), "t", {"boundary.correction=true"}));
    REQUIRE(both.params.boundary.static_objects.size() == 2);
    const ContactField& second = both.params.boundary.static_objects[1];
    CHECK(second.field.first == std::uint32_t(c.field.nx * c.field.ny * c.field.nz));
    CHECK(both.params.boundary.static_object_distances.size() ==
          second.field.first + std::size_t(second.field.nx) * second.field.ny * second.field.nz);
    const View<const Real> values{both.params.boundary.static_object_distances.data(), both.params.boundary.static_object_distances.size()};
    REQUIRE(second.field.sample(values, Vec3{0.15f, 0.15f, 0.15f}, d, g));
    CHECK(std::abs(d + 0.02f) < 1e-4f);  // the box's centre, 0.02 m from each face
    REQUIRE(both.params.boundary.static_objects[0].field.sample(values, Vec3{0.15f, 0.1f, 0.1f}, d, g));
    CHECK(std::abs(d + 0.03f) < 0.0015f);
    // None without the correction, for a moving object, or with no fluid to correct.
    CHECK(build_setup(parse_scene_text(tiny_scene_text(object), "t", {"boundary.correction=false"}))
              .params.boundary.static_objects.empty());
    CHECK(build_setup(parse_scene_text(tiny_scene_text(object), "t", {"boundary.correction=true", "objects.0.kind=\"rigid\""}))
              .params.boundary.static_objects.empty());
    CHECK(build_setup(parse_scene_text(tiny_scene_text(object), "t", {"boundary.correction=true", "fluid_blocks=[]"}))
              .params.boundary.static_objects.empty());
}

// h a rounding error above r0 passes the scene's range (r0, 4 r0] but leaves no wall placement
// that gives the fluid its rest density (sampling/wall_gap.hpp): refused at set-up, naming the key.
TEST_CASE("a support radius within rounding of the spacing is refused, naming the key") {
    const Scene s = parse_scene_text(tiny_scene_text(), "t", {"fluid.support_radius=0.02000001"});
    try {
        build_setup(s);
        FAIL("build_setup accepted h = r0 (1 + 5e-7)");
    } catch (const InputError& e) {
        const std::string message = e.what();
        CAPTURE(message);
        CHECK(contains(message, "fluid.support_radius"));
        CHECK(contains(message, "fluid.spacing"));
        CHECK(message.find('\n') == std::string::npos);
    }
}

TEST_CASE("a scene too large to build is refused before allocating") {
    const Scene s = parse_scene_text(tiny_scene_text(), "t", {"domain.max=[1000,1000,1000]", "fluid.spacing=0.001"});
    CHECK_THROWS_AS(build_setup(s), InputError);
}

// One id space: a particle's object number is its body's index in setup.solids, the objects first
// and then the static boxes (static bodies with no mesh).
TEST_CASE("objects and static boxes share one id space, the index of their body in the setup") {
    const Scene s = parse_scene_text(
        tiny_scene_text(R"("static_boxes": [ { "min": [0.15, 0, 0.15], "max": [0.2, 0.05, 0.2] } ],
  "objects": [ { "name": "cube", "mesh": { "procedural": "box:x=0.04,y=0.04,z=0.04" },
                 "transform": { "translation": [0.15, 0.15, 0.05] }, "kind": "rigid" } ])"),
        "t");
    const SimulationSetup setup = build_setup(s);
    REQUIRE(setup.solids.size() == 2);
    CHECK(setup.solids[0].name == "cube");
    CHECK(setup.solids[1].kind == SolidKind::kStatic);
    CHECK(setup.solids[1].name == "static_box0");
    long cube = 0, box = 0, other = 0;
    for (std::size_t i = 0; i < setup.type.size(); ++i) {
        if (setup.object[i] < 0) continue;
        if (setup.object[i] == 0 && setup.type[i] != kStaticBoundary) ++cube;
        else if (setup.object[i] == 1 && setup.type[i] == kStaticBoundary) ++box;
        else ++other;
    }
    CHECK(cube > 0);
    CHECK(box > 0);
    CHECK(other == 0);
}

TEST_CASE("the setup has fluid first, walls and static boxes with their object ids") {
    const Scene s = parse_scene_text(
        tiny_scene_text(R"("static_boxes": [ { "min": [0.15, 0, 0.15], "max": [0.2, 0.05, 0.2] } ])"), "t");
    const SimulationSetup setup = build_setup(s);
    const ParticleCounts c = count_particles(setup);
    CHECK(c.by_type[kFluid] == 125);
    bool has_wall = false, has_box = false;
    for (std::size_t i = 0; i < setup.type.size(); ++i) {
        if (setup.type[i] == kFluid) CHECK(setup.object[i] == -1);
        if (setup.type[i] == kStaticBoundary && setup.object[i] == -1) has_wall = true;
        if (setup.type[i] == kStaticBoundary && setup.object[i] == 0) has_box = true;
    }
    CHECK(has_wall);
    CHECK(has_box);
    CHECK(estimate_particle_count(s) > 0);
    const Scene open = parse_scene_text(tiny_scene_text(), "t", {"boundary.walls=false"});
    CHECK(count_particles(build_setup(open)).by_type[kStaticBoundary] == 0);
}

MW_TEST_MAIN

// The host-memory check's estimate (apps/cli_common.cpp) grows the neighbour lists' share with
// the neighbour count, (h / 2 r0)³; checked against the layouts the simulation really allocates
// (its device_bytes, built on the host) for the default dam break at h = 2 r0 and 2.5 r0.
TEST_CASE("the host-memory estimate grows with the kernel's support as the neighbour lists do") {
    const Scene narrow = load_scene("");
    const Scene wide = load_scene("", {"fluid.support_radius=0.05", "fluid.kernel=wendland_c2"});
    auto bytes = [](const Scene& s, const char* layout) {
        return double(probe_on_host(build_setup(s), layout)->device_bytes());
    };
    const double lists_narrow = bytes(narrow, "openmp"), grid_narrow = bytes(narrow, "cuda");
    const double lists_wide = bytes(wide, "openmp");
    const double measured_growth = (lists_wide - lists_narrow) / (lists_narrow - grid_narrow);
    const double estimate_narrow = host_bytes_needed(narrow, "openmp", true);
    const double estimated_growth = (host_bytes_needed(wide, "openmp", true) - estimate_narrow) /
                                    (estimate_narrow - host_bytes_needed(narrow, "cuda", true));
    // Measured 0.955 and estimated 0.953 (the lists hold about (2.5/2)³ - 1 more).
    MESSAGE("lists' growth from h = 2 to 2.5 r0, in units of their share at 2 r0: measured "
            << measured_growth << ", estimated " << estimated_growth);
    CHECK(estimated_growth == doctest::Approx(measured_growth).epsilon(0.25));
    // At h = 2 r0 the estimate is the one calibrated against the 1M dam break's peak memory.
    CHECK(estimate_narrow == doctest::Approx(48000 * 420.0 + 76346 * 60.0).epsilon(0.05));
}
