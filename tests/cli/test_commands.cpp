// The `meltwater` program end to end: bad input of every kind, info, backends, and small runs
// whose outputs are checked (stats.csv, summary.json, frames read back with meshio).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <nlohmann/json.hpp>

#include "backend/config.hpp"
#include "cli_helpers.hpp"
#include "sampling/obj_loader.hpp"
#include "tests/skip.hpp"

using namespace cli_test;
namespace fs = std::filesystem;

namespace {
std::string tiny() {
    static const std::string path = scene_file("tiny.json", tiny_scene_text());
    return path;
}
}  // namespace

TEST_CASE("bad input: files") {
    check_rejected(run("info /no/such/scene.json"), {"/no/such/scene.json", "cannot open"});
    check_rejected(run("run /no/such/scene.json --out " + out_dir("never")), {"/no/such/scene.json"});
    CHECK(!fs::exists(scratch_dir() + "/never"));
    check_rejected(run("info " + scene_file("broken.json", "{ \"domain\": { \"min\": [0,0,0], }")),
                   {"broken.json", "malformed JSON", "line 1"});
    check_rejected(run("info " + scene_file("empty.json", "")), {"empty.json", "malformed JSON"});
    check_rejected(run("info " + scene_file("list.json", "[1,2,3]")), {"list.json", "JSON object"});
    check_rejected(run("info " + scratch_dir()), {"is a directory"});
}

TEST_CASE("bad input: scene keys and values") {
    check_rejected(run("info " + scene_file("unknown.json", tiny_scene_text(R"("solverr": {})"))),
                   {"unknown.json", "solverr", "unknown key"});
    check_rejected(run("info " + tiny() + " --set solver.etaa=0.1"), {"solver.etaa"});
    check_rejected(run("info " + tiny() + " --set solver.eta=2"), {"solver.eta", "(0, 1)"});
    check_rejected(run("info " + tiny() + " --set fluid.spacing=abc"), {"fluid.spacing", "expected a number"});
    check_rejected(run("info " + tiny() + " --set fluid.spacing=-0.01"), {"fluid.spacing", "> 0"});
    check_rejected(run("info " + tiny() + " --set boundary.layers=2.5"), {"boundary.layers", "integer"});
    check_rejected(run("info " + tiny() + " --set dimensions=4"), {"dimensions", "2 or 3"});
    check_rejected(run("info " + tiny() + " --set 'fluid_blocks.0.max=[5,5,5]'"), {"fluid_blocks[0]", "domain"});
    check_rejected(run("info " + tiny() + " --set solver.dt_mode=sometimes"), {"solver.dt_mode", "sometimes"});
    check_rejected(run("info " + tiny() + " --set nokey"), {"--set nokey", "KEY=VALUE"});
    check_rejected(run("info " + scene_file("nodomain.json", R"({"fluid": {"spacing": 0.02}})")), {"domain.min"});
    // Solver and neighbour switches.
    check_rejected(run("info " + tiny() + " --set fluid.wall_viscosity=-1"), {"fluid.wall_viscosity"});
    check_rejected(run("info " + tiny() + " --set solver.eta_max=1.5"), {"solver.eta_max"});
    check_rejected(run("info " + tiny() + " --set neighbors.cells_per_support=3"), {"neighbors.cells_per_support"});
    check_rejected(run("info " + tiny() + " --set neighbors.lists=maybe"), {"neighbors.lists", "maybe"});
    // Numbers the simulation's scalar type cannot hold, and JSON numbers no double holds.
    constexpr bool float_build = sizeof(mw::Real) == 4;
    if (float_build) check_rejected(run("info " + tiny() + " --set 'gravity=[0,1e39,0]'"), {"gravity[1]", "1e+39"});
    check_rejected(run("info " + tiny() + " --set solver.dt=1e-300"), {"solver.dt"});
    check_rejected(run("info " + tiny() + " --set fluid.spacing=1e999"), {"fluid.spacing", "1e999"});
    check_rejected(run("info " + scene_file("overflow.json", tiny_scene_text(R"("run": {"end_time": 1e999})"))),
                   {"overflow.json", "1e999"});
    check_rejected(run("info " + tiny() + " --set run.end_time=1e300"), {"run.end_time"});
    // A section replaced by a value, then used as a section.
    check_rejected(run("info " + tiny() + " --set fluid=5 --set fluid.spacing=0.02"), {"fluid", "not a section"});
}

TEST_CASE("bad input: command line") {
    check_rejected(run("frobnicate"), {"frobnicate"});
    check_rejected(run("run " + tiny() + " --frobnicate"), {"frobnicate"});
    check_rejected(run("run " + tiny() + " --steps 2 --time 0.1"), {"--steps", "--time"});
    check_rejected(run("run " + tiny() + " --steps 0"), {"--steps"});
    // A value that does not parse is reported with the option it was given to, in every spelling.
    check_rejected(run("run " + tiny() + " --steps many"), {"--steps", "whole number", "'many'"});
    check_rejected(run("run " + tiny() + " --threads=2.5"), {"--threads", "whole number", "'2.5'"});
    check_rejected(run("run " + tiny() + " --steps 99999999999999999999"), {"--steps", "out of range"});
    check_rejected(run("run " + tiny() + " --time 1e999"), {"--time", "out of range"});
    check_rejected(run("run " + tiny() + " --time nan"), {"--time", "finite", "'nan'"});
    check_rejected(run("run " + tiny() + " --time 1s"), {"--time", "'1s'"});
    check_rejected(run("run " + tiny() + " --quiet=maybe"), {"--quiet", "'maybe'"});
    check_rejected(run("run " + tiny() + " --steps"), {"--steps", "needs a value"});
    // An option where a value should be is not taken as the value (cxxopts would take it).
    check_rejected(run("run " + tiny() + " --steps --quiet"), {"--steps", "needs a value", "'--quiet'"});
    check_rejected(run("run " + tiny() + " --steps 1 --out -q"), {"--out", "needs a value", "'-q'"});
    // ... but a value written with '=' or after "--" is taken as written, and numbers are values.
    check_rejected(run("info " + tiny() + " --backend=-x"), {"--backend", "expected auto, cuda or openmp", "'-x'"});
    check_rejected(run("info -- -x.json"), {"-x.json", "cannot open"});
    check_rejected(run("run " + tiny() + " --time -inf"), {"--time", "finite", "'-inf'"});
    check_rejected(run("run " + tiny() + " --steps -3"), {"--steps", "at least 1", "-3"});
    check_rejected(run("sample x --spacing abc --out " + scratch_dir() + "/never"), {"--spacing", "'abc'"});
    check_rejected(run("sample x --spacing 0.1 --directions three --out " + scratch_dir() + "/never"),
                   {"--directions", "'three'"});
    check_rejected(run("run " + tiny() + " --time -1"), {"--time"});
    check_rejected(run("run " + tiny() + " --threads 0"), {"--threads"});
    check_rejected(run("run " + tiny() + " --backend vulkan"), {"--backend", "vulkan"});
    check_rejected(run("info " + tiny() + " --backend vulkan"), {"--backend", "vulkan"});
    check_rejected(run("run " + tiny() + " " + tiny()), {"one scene"});
    check_rejected(run("run " + tiny() + " --set"), {"--set"});
    check_rejected(run("run " + tiny() + " --steps 1 --out /proc/meltwater_cannot_write"), {"/proc/meltwater_cannot_write"});
    // A directory that exists but cannot be written (even by root): refused before simulating.
    check_rejected(run("run " + tiny() + " --steps 1 --out /proc"), {"/proc", "cannot write"});
    // cxxopts would silently keep the last of a repeated option.
    check_rejected(run("run " + tiny() + " --steps 1 --out a --out b"), {"--out", "more than once"});
    check_rejected(run("run " + tiny() + " --steps 1 --steps 2"), {"--steps", "more than once"});
    // libgomp crashes on tens of thousands of threads.
    check_rejected(run("run " + tiny() + " --steps 1 --threads 100000"), {"--threads", "1024"});
    check_rejected(run("backends extra"), {"extra"});
    // A control character in what the user wrote stays escaped: the message is still one line.
    check_rejected(run("info " + tiny() + " --set 'name=\"a\\nb\"'"), {"name", "a\\nb"});
    check_rejected(run("info /dev/zero"), {"/dev/zero", "64 MiB"});
    check_rejected(run("run " + tiny() + " --time 1e300"), {"--time", "1e+300"});
    // A domain of 1e9 supports: its cell count once overflowed int and passed the grid check.
    check_rejected(run("run " + tiny() + " --steps 1 --out " + out_dir("wide") +
                       " --set 'domain.max=[1e9,0.2,0.2]' --set boundary.walls=false"),
                   {"domain is too large"});
    CHECK(!fs::exists(scratch_dir() + "/wide"));
}

TEST_CASE("bad input: a failed run leaves no directory it made, and no run writes over a directory") {
    // Every missing level of a nested --out is removed again, not only the last.
    const std::string nested = out_dir("nested");
    check_rejected(run("run " + tiny() + " --steps 1 --out " + nested + "/a/b --set 'domain.max=[1e9,0.2,0.2]' "
                       "--set boundary.walls=false"),
                   {"domain is too large"});
    CHECK(!fs::exists(nested));
    // summary.json is renamed into place at the end: a directory of that name is found first.
    const std::string taken = out_dir("taken");
    fs::create_directories(taken + "/summary.json");
    check_rejected(run("run " + tiny() + " --steps 1 --out " + taken), {"summary.json", "is a directory"});
    CHECK(!fs::exists(taken + "/stats.csv"));
    // A file named frames is found before the simulation is built, too.
    const std::string framed = out_dir("framed");
    fs::create_directories(framed);
    std::ofstream(framed + "/frames") << "not a directory\n";
    check_rejected(run("run " + tiny() + " --steps 1 --out " + framed), {"frames", "is a file"});
    CHECK(!fs::exists(framed + "/stats.csv"));
    // Text that is not UTF-8 (JSON files are checked by the parser; a --set value that is not JSON
    // is taken as a plain string) fails at once, not after the run when summary.json is written.
    check_rejected(run("run " + tiny() + " --steps 1 --out " + out_dir("latin1") + " --set 'description=caf\xe9'"),
                   {"description", "UTF-8"});
    CHECK(!fs::exists(scratch_dir() + "/latin1"));
}

TEST_CASE("bad input: a scene larger than the host's memory is refused before allocating") {
    // About 171 million fluid particles (and 7 million wall particles), under the 200 million
    // cap: some 72 GB. Where the machine has that much, the check would let it through and info
    // would build it, so skip.
    std::ifstream meminfo("/proc/meminfo");
    std::string line;
    double available_kib = 0;
    while (std::getline(meminfo, line))
        if (std::sscanf(line.c_str(), "MemAvailable: %lf kB", &available_kib) == 1) break;
    if (available_kib == 0 || available_kib > 60e6) {
        MW_SKIP("MemAvailable unknown or above 60 GB: the host-memory refusal is not tested here");
        return;
    }
    const std::string huge = "--set fluid.spacing=0.00036 --set 'fluid_blocks.0.max=[0.2,0.2,0.2]' --set fluid.support_radius=0.00072";
    check_rejected(run("info " + tiny() + " " + huge), {"host memory", "available"}, 3);
    const std::string dir = out_dir("huge");
    check_rejected(run("run " + tiny() + " " + huge + " --out " + dir), {"host memory", "available"}, 3);
    CHECK(!fs::exists(dir));
}

TEST_CASE("--backend cuda without a usable GPU is a clear error") {
    const Result b = run("backends --json");
    REQUIRE(b.code == 0);
    const auto j = nlohmann::json::parse(b.out);
    bool cuda_available = false;
    for (const auto& e : j["backends"])
        if (e["name"] == "cuda") cuda_available = e["available"].get<bool>();
    if (cuda_available) {
        MW_SKIP("a GPU is available here; the no-GPU error is not tested");
        return;
    }
    check_rejected(run("run " + tiny() + " --steps 1 --backend cuda --out " + out_dir("cuda")), {"cuda"}, 3);
}

TEST_CASE("backends lists what was compiled") {
    const Result r = run("backends");
    CHECK(r.code == 0);
    CHECK(contains(r.out, "openmp"));
    CHECK(contains(r.out, "cuda"));
    CHECK(contains(r.out, "--backend auto picks"));
    // The JSON form against how this build was configured (MW_CUDA_COMPILED from CMake).
    const Result j = run("backends --json");
    REQUIRE(j.code == 0);
    const auto listed = nlohmann::json::parse(j.out);
    bool saw_cuda = false, saw_openmp = false;
    for (const auto& b : listed["backends"]) {
        if (b["name"] == "cuda") {
            saw_cuda = true;
            CHECK(b["compiled"].get<bool>() == bool(MW_CUDA_COMPILED));
        }
        if (b["name"] == "openmp") {
            saw_openmp = true;
            CHECK(b["compiled"].get<bool>());
            CHECK(b["available"].get<bool>());
        }
    }
    CHECK(saw_cuda);
    CHECK(saw_openmp);
}

TEST_CASE("info: the built-in default scene and a small one") {
    const Result d = run("info");
    CAPTURE(d.err);
    REQUIRE(d.code == 0);
    CHECK(contains(d.out, "dam_break"));
    CHECK(contains(d.out, "fluid 48,000"));
    CHECK(contains(d.out, "memory"));
    CHECK(contains(d.out, "stages"));
    CHECK(contains(d.out, "density error < 0.01 average, < 0.05 peak"));  // the stopping rule, default peak bound
    CHECK(contains(run("info --set solver.eta_max=0").out, "< 0.01 average (peak unbounded)"));
    // The guards: the default dam break's domain is 1 m tall, so its speed scale is sqrt(2 g) m/s.
    CHECK(contains(d.out, "guards      the run stops at a peak density error above 1 (solver.max_density_error); "
                          "more than 1% of the fluid lost (boundary.max_lost_fraction); a particle faster than "
                          "solver.max_speed 88.59 m/s (20 times the scene's 4.43 m/s"));
    CHECK(contains(run("info --set solver.max_speed=5").out, "a particle faster than solver.max_speed 5 m/s\n"));

    const Result t = run("info " + tiny() + " --json");
    CAPTURE(t.err);
    REQUIRE(t.code == 0);
    const auto j = nlohmann::json::parse(t.out);
    CHECK(j["particles"]["fluid"] == 125);
    CHECK(j["particles"]["static_boundary"].get<long>() > 0);
    CHECK(j["device_bytes"].get<long>() > 0);
    CHECK(j["stages"].size() > 0);
    CHECK(j["scene"]["solver"]["eta"].get<double>() == doctest::Approx(0.01));
    // The tiny scene's domain is 0.2 m tall.
    CHECK(j["speed_limit"].get<double>() == doctest::Approx(20 * std::sqrt(2 * 9.81 * 0.2)));

    // A stage the scene does not need is not listed and holds no memory: viscosity is off by
    // default; switching it on adds the stage and its per-particle acceleration array.
    const Result v = run("info " + tiny() + " --json --set fluid.viscosity=0.01");
    REQUIRE(v.code == 0);
    const auto jv = nlohmann::json::parse(v.out);
    const auto lists_viscosity = [](const nlohmann::json& stages) {
        for (const auto& s : stages)
            if (s == "viscosity") return true;
        return false;
    };
    CHECK(!lists_viscosity(j["stages"]));
    CHECK(lists_viscosity(jv["stages"]));
    CHECK(jv["stages"].size() == j["stages"].size() + 1);
    CHECK(jv["device_bytes"].get<long>() > j["device_bytes"].get<long>());

    // --backend picks the layout estimated: CUDA gathers from the grid (no neighbour lists), so
    // it needs less than OpenMP's lists; no GPU is needed to estimate for one.
    const Result c = run("info " + tiny() + " --json --backend cuda");
    const Result o = run("info " + tiny() + " --json --backend openmp");
    REQUIRE(c.code == 0);
    REQUIRE(o.code == 0);
    const auto jc = nlohmann::json::parse(c.out), jo = nlohmann::json::parse(o.out);
    CHECK(jc["backend"] == "cuda");
    CHECK(jo["backend"] == "openmp");
    CHECK(jc["device_bytes"].get<long>() < jo["device_bytes"].get<long>());
}

TEST_CASE("info: the kernel, and a warning for the cubic spline at a support it is unstable at") {
    const Result d = run("info");
    REQUIRE(d.code == 0);
    CHECK(contains(d.out, "2 r0, cubic_spline kernel"));
    CHECK(!contains(d.out, "warning"));
    // The paper's h = 2.5 r0 with the cubic spline: warned (docs/solver.md, "Kernels").
    const Result wide = run("info --set fluid.support_radius=0.05");
    REQUIRE(wide.code == 0);
    for (const char* expected : {"warning", "pairing instability", "wendland_c2"}) CHECK(contains(wide.out, expected));
    const Result wendland = run("info --set fluid.support_radius=0.05 --set fluid.kernel=wendland_c2 --json");
    REQUIRE(wendland.code == 0);
    const auto j = nlohmann::json::parse(wendland.out);
    CHECK(j["warnings"].empty());
    CHECK(j["scene"]["fluid"]["kernel"] == "wendland_c2");
    // The walls sit where the chosen kernel starts the fluid at rest: Wendland C2's gap differs.
    const auto cubic = nlohmann::json::parse(run("info --set fluid.support_radius=0.05 --json").out);
    CHECK(cubic["warnings"].size() == 1);
    CHECK(j["wall_gap_m"].get<double>() < 0.97 * cubic["wall_gap_m"].get<double>());  // 0.699 r0 against 0.740 r0
    // A run says it too.
    const Result r = run("run --set fluid.support_radius=0.05 --steps 1 --quiet --set 'output.formats=[]' --out " +
                         scratch_dir() + "/wide");
    CHECK(r.code == 0);
    CHECK(contains(r.err, "pairing instability"));
    const auto summary = nlohmann::json::parse(slurp(scratch_dir() + "/wide/summary.json"));
    REQUIRE(summary["warnings"].size() == 1);
    CHECK(contains(summary["warnings"][0].get<std::string>(), "pairing instability"));
}

TEST_CASE("info: the velocity-position correction, on in the default scene, named with what it covers") {
    const Result on = run("info");
    REQUIRE(on.code == 0);
    CHECK(contains(on.out, "velocity-position correction on (boundary.correction): fluid moving into a boundary stops "
                           "about r0 from the walls' layer\n"));
    const Result boxes = run("info --set boundary.walls=false --set 'static_boxes=[{\"min\":[1,0,0.3],\"max\":[1.2,0.2,0.5]}]'");
    REQUIRE(boxes.code == 0);
    CHECK(contains(boxes.out, "fluid moving into a boundary stops about r0 from a static box\n"));
    const Result objects = run("info --set 'objects=[{\"mesh\":{\"procedural\":\"sphere:radius=0.1\"},"
                               "\"transform\":{\"translation\":[1.2,0.3,0.4]},\"kind\":\"static\"}]'");
    REQUIRE(objects.code == 0);
    CHECK(contains(objects.out, "about r0 from the walls' layer, 0.45 r0 from a static object's surface (1 object(s); "
                                "distance grids of "));
    CHECK(contains(objects.out, "spacing up to 0.5 r0)\n"));
    CHECK(!contains(objects.out, "coarser than r0/2"));
    const Result off = run("info --set boundary.correction=false");
    REQUIRE(off.code == 0);
    CHECK(contains(off.out, "velocity-position correction off"));
    // Off with a static object as the only boundary: still said.
    const Result object_only = run("info --set boundary.walls=false --set boundary.correction=false --set "
                                   "'objects=[{\"mesh\":{\"procedural\":\"sphere:radius=0.1\"},"
                                   "\"transform\":{\"translation\":[1.2,0.3,0.4]},\"kind\":\"static\"}]'");
    REQUIRE(object_only.code == 0);
    CHECK(contains(object_only.out, "velocity-position correction off"));
    const Result open = run("info --set boundary.walls=false");
    REQUIRE(open.code == 0);
    CHECK(!contains(open.out, "velocity-position correction"));  // nothing to correct against
    // On unless the scene turns it off: the paper's method.
    const Result unasked = run("info " + tiny());
    REQUIRE(unasked.code == 0);
    CHECK(contains(unasked.out, "velocity-position correction on (boundary.correction)"));
    check_rejected(run("info --set boundary.correction=1"), {"boundary.correction"});
}

TEST_CASE("bad input: a moving object that starts inside another object or a static box") {
    // 0.04 m cubes at r0 = 0.02 m: 2 x 2 x 2 inner particles, 0.01 m inside each face.
    const auto cube = [](const std::string& kind, double x) {
        return R"({"kind": ")" + kind + R"(", "mesh": {"procedural": "box:x=0.04,y=0.04,z=0.04"},
                   "transform": {"translation": [)" + std::to_string(x) + ", 0.16, 0.16]}}";
    };
    const auto scene = [&](const std::string& name, const std::string& objects, const std::string& boxes = "") {
        return scene_file(name + ".json", tiny_scene_text((boxes.empty() ? "" : R"("static_boxes": [)" + boxes + "],\n") +
                                                          R"("objects": [)" + objects + "]"));
    };
    // Half a cube deep: the four inner particles of one face lie inside the other cube.
    check_rejected(run("info " + scene("overlap", cube("elastic", 0.08) + "," + cube("rigid", 0.1))),
                   {"objects[0]", "overlaps objects[1]", "4 of its 8 inner particles"});
    check_rejected(run("info " + scene("in_box", cube("elastic", 0.08), R"({"min": [0.075, 0.12, 0.12], "max": [0.2, 0.2, 0.2]})")),
                   {"objects[0]", "overlaps static_boxes[0]", "4 of its 8"});
    // Three objects, one mesh tested against the inner particles of both others at once: a static
    // cube turned 45 degrees about z (a diamond 0.0283 m from centre to corner in x and y, at
    // (0.1, 0.16)); a rigid cube sunk into it, whose four inner particles at x = 0.11 lie inside it;
    // and an elastic cube beside it whose two inner particles at (0.075, 0.135) lie inside the
    // diamond's bounding box but outside the diamond, so they are tested and must not count.
    const std::string diamond = R"({"kind": "static", "mesh": {"procedural": "box:x=0.04,y=0.04,z=0.04"},
                   "transform": {"rotation_deg": [0, 0, 45], "translation": [0.1, 0.16, 0.16]}})";
    const std::string beside = R"({"kind": "elastic", "mesh": {"procedural": "box:x=0.04,y=0.04,z=0.04"},
                   "transform": {"translation": [0.065, 0.125, 0.16]}})";
    const std::string sunk = R"({"kind": "rigid", "mesh": {"procedural": "box:x=0.04,y=0.04,z=0.04"},
                   "transform": {"translation": [0.12, 0.16, 0.16]}})";
    check_rejected(run("info " + scene("three", beside + "," + sunk + "," + diamond)),
                   {"objects[1]", "overlaps objects[2]", "4 of its 8 inner particles"});
    // Without the sunk cube the scene is accepted: the elastic cube's two candidates are outside.
    CHECK(run("info " + scene("two", beside + "," + diamond)).code == 0);
    // Touching is fine, and so are static solids sunk into one another (scenery).
    CHECK(run("info " + scene("touching", cube("elastic", 0.08) + "," + cube("elastic", 0.12))).code == 0);
    CHECK(run("info " + scene("static_pair", cube("static", 0.08) + "," + cube("static", 0.1),
                              R"({"min": [0.07, 0.12, 0.12], "max": [0.2, 0.2, 0.2]})")).code == 0);
}

TEST_CASE("a static box and an object inside the fluid carve it out, and the run starts at rest") {
    // The tiny scene's block (125 particles, 0.1 m cube in a corner of the tank) with a static box
    // standing in one corner of it and an elastic cube in another.
    const std::string folder = scratch_dir() + "/carved";
    fs::create_directories(folder);
    write_text(folder + "/scene.json",
               tiny_scene_text(R"("static_boxes": [{"min": [0, 0, 0], "max": [0.04, 0.04, 0.04]}],
                   "objects": [{"mesh": {"procedural": "box:x=0.04,y=0.04,z=0.04"},
                                "transform": {"translation": [0.08, 0.02, 0.08]}}])"));
    const Result r = run("info " + folder + "/scene.json --json");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    const auto j = nlohmann::json::parse(r.out);
    const long fluid = j["particles"]["fluid"].get<long>(), carved = j["fluid_carved"].get<long>();
    CHECK(fluid + carved == 125);
    // Each solid takes the 2 x 2 x 2 lattice points inside it and the layer half a spacing from
    // its faces: a 3 x 3 x 3 corner of the block each. The two corners share the 3 points at
    // x = z = 0.05 m: 27 + 27 - 3 = 51 particles.
    CHECK(carved == 51);
    CHECK(contains(run("info " + folder + "/scene.json").out, "carved      51 fluid particles"));
    // Uncarved, the fluid next to the solids started 55% over-dense and the first step blew it
    // apart; carved, it starts at rest.
    const std::string out = out_dir("carved_run");
    const Result started = run("run " + folder + "/scene.json --steps 3 --threads 1 --out " + out);
    CAPTURE(started.err);
    REQUIRE(started.code == 0);
    const auto summary = read_json(out + "/summary.json");
    CHECK(summary["density_error"]["max"].get<double>() < 0.03);
    // run reports the carving too: on its first line and in summary.json.
    CHECK(contains(started.err, "(74 fluid, "));
    CHECK(contains(started.err, "; 51 fluid carved out where solids stand)"));
    CHECK(summary["fluid_carved"].get<long>() == 51);
}

TEST_CASE("the cantilever scene: its mesh is written per frame, and the pin holds the left end") {
    // scenes/cantilever.json end to end: a 0.5 x 0.1 x 0.1 m box beam centred at (0.35, 0.7, 0.2),
    // IBPs with x < 0.14 pinned (half-space, normal +x). 50 steps of 1 ms: frames at t = 0 and 1/30 s.
    const std::string dir = out_dir("cantilever");
    const Result r = run("run " + std::string(MW_SOURCE_DIR) + "/scenes/cantilever.json --steps 50 --threads 1 --quiet --out " + dir);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.out, "no fluid"));
    // Read back with the project's own OBJ reader (which also checks the faces' indices).
    const mw::TriangleMesh rest_mesh = mw::load_obj(dir + "/frames/object_beam_00000.obj");
    const mw::TriangleMesh later_mesh = mw::load_obj(dir + "/frames/object_beam_00001.obj");
    const std::vector<mw::Vec3d>& rest = rest_mesh.vertices;
    const std::vector<mw::Vec3d>& later = later_mesh.vertices;
    // The box's 12 triangles refined so that no edge exceeds r0 (its GPs' mesh, docs/sampling.md),
    // its 8 corners first; every frame has the same mesh.
    REQUIRE(rest.size() > 8);
    REQUIRE(later.size() == rest.size());
    CHECK(rest_mesh.triangle_count() > 12);
    CHECK(later_mesh.triangles == rest_mesh.triangles);
    // Frame 0 is the transformed mesh: the first 8 vertices are the corners of [0.1, 0.6] x
    // [0.65, 0.75] x [0.15, 0.25], and every vertex lies on one of its faces.
    auto on = [](double x, double a, double b) { return std::fabs(x - a) < 1e-6 || std::fabs(x - b) < 1e-6; };
    for (std::size_t k = 0; k < 8; ++k) {
        CHECK(on(rest[k][0], 0.1, 0.6));
        CHECK(on(rest[k][1], 0.65, 0.75));
        CHECK(on(rest[k][2], 0.15, 0.25));
    }
    for (const auto& x : rest) {
        REQUIRE((on(x[0], 0.1, 0.6) || on(x[1], 0.65, 0.75) || on(x[2], 0.15, 0.25)));
        REQUIRE((x[0] > 0.1 - 1e-6 && x[0] < 0.6 + 1e-6 && x[1] > 0.65 - 1e-6 && x[1] < 0.75 + 1e-6 &&
                 x[2] > 0.15 - 1e-6 && x[2] < 0.25 + 1e-6));
    }
    // The free end sags; the pinned end stays (its corners move only through the unpinned IBPs
    // within a support radius that Eq. 19 also weighs). A pin of the wrong sign holds the other end.
    double pinned_end = 0, free_end = 0;
    for (std::size_t k = 0; k < 8; ++k) {
        const double moved = (later[k] - rest[k]).norm();
        if (rest[k][0] < 0.35) pinned_end = std::max(pinned_end, moved);
        else free_end = std::max(free_end, moved);
        if (rest[k][0] > 0.35) CHECK(later[k][1] < rest[k][1] - 1e-3);  // fell by more than 1 mm
    }
    MESSAGE("after 1/30 s the free end moved " << free_end << " m, the pinned end " << pinned_end << " m");
    CHECK(pinned_end < 0.1 * free_end);
}

TEST_CASE("the resolved scene names mesh files absolutely, so it runs from anywhere") {
    const std::string folder = scratch_dir() + "/mesh_scene";
    fs::create_directories(folder + "/elsewhere");
    // A 0.1 m cube, outward-facing triangles.
    write_text(folder + "/cube.obj",
               "v 0 0 0\nv 0.1 0 0\nv 0.1 0.1 0\nv 0 0.1 0\nv 0 0 0.1\nv 0.1 0 0.1\nv 0.1 0.1 0.1\nv 0 0.1 0.1\n"
               "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\n"
               "f 2 3 7\nf 2 7 6\n");
    write_text(folder + "/scene.json", tiny_scene_text(R"("objects": [{"mesh": {"file": "cube.obj"},
        "transform": {"translation": [0.1, 0.05, 0.05]}}])"));
    const Result r = run("info " + folder + "/scene.json --json");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    const auto j = nlohmann::json::parse(r.out);
    const std::string file = j["scene"]["objects"][0]["mesh"]["file"];
    CHECK(fs::path(file).is_absolute());
    CHECK(fs::equivalent(file, folder + "/cube.obj"));
    write_text(folder + "/elsewhere/resolved.json", j["scene"].dump(2));
    CHECK(run("info " + folder + "/elsewhere/resolved.json").code == 0);
}

TEST_CASE("run: two steps write frames, stats.csv and summary.json") {
    const std::string dir = out_dir("two_steps");
    const Result r = run("run " + tiny() + " --steps 2 --backend openmp --threads 1 --out " + dir + " --set solver.eta=0.02");
    CAPTURE(r.err);
    CAPTURE(r.out);
    REQUIRE(r.code == 0);
    CHECK(contains(r.out, "results in"));
    CHECK(fs::exists(dir + "/frames/particles_00000.vtu"));
    CHECK(fs::exists(dir + "/frames/particles.pvd"));

    const std::string csv = slurp(dir + "/stats.csv");
    const std::string header = csv.substr(0, csv.find('\n'));
    for (const char* column : {"step", "time", "dt", "iterations", "density_error_avg", "density_error_max",
                               "max_speed", "kinetic_energy", "lost_particles", "dt_retries", "diverged",
                               "unconverged", "ms_neighbors", "ms_pcisph", "ms_total"})
        CHECK_MESSAGE(contains("," + header + ",", std::string(",") + column + ","), column);
    CHECK(count_lines(csv) == 3);  // header + one row per step
    // Every row has as many values as the header has columns.
    const auto columns = [](const std::string& line) { return std::count(line.begin(), line.end(), ',') + 1; };
    const std::size_t row_start = csv.find('\n') + 1;
    CHECK(columns(csv.substr(row_start, csv.find('\n', row_start) - row_start)) == columns(header));

    const auto s = read_json(dir + "/summary.json");
    for (const char* key : {"status", "backend", "device", "steps", "particles", "ms_per_step", "density_error",
                            "bytes_per_particle", "scene", "lost_particles", "simulated_time", "wall_seconds",
                            "particle_steps_per_second", "iterations", "retried_steps", "diverged_steps",
                            "unconverged_steps"})
        CHECK_MESSAGE(s.contains(key), key);
    CHECK(s["status"] == "completed");
    CHECK(s["backend"] == "openmp");
    CHECK(s["steps"] == 2);
    CHECK(s["particles"]["fluid"] == 125);
    CHECK(s["ms_per_step"].contains("total"));
    CHECK(s["density_error"].contains("avg"));
    CHECK(s["density_error"].contains("max"));
    CHECK(s["scene"]["solver"]["eta"].get<double>() == doctest::Approx(0.02));  // override applied
    CHECK(s["scene"]["fluid"]["support_radius"].get<double>() == doctest::Approx(0.04));  // default filled in
    for (const auto& entry : fs::directory_iterator(dir)) CHECK(!contains(entry.path().string(), ".tmp"));
}

TEST_CASE("run: stats.csv follows each moving object's centre, and summary.json counts the particles at the end") {
    // The tiny scene's rigid box (500 kg/m3) starts in the air beside the fluid block, its centre
    // at y = 0.1 m, and falls.
    const std::string dir = out_dir("centroid");
    const Result r = run("run " + tiny_scene_with_box("centroid.json") + " --steps 10 --quiet --out " + dir);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    std::istringstream csv(slurp(dir + "/stats.csv"));
    std::string header, first, last, line;
    std::getline(csv, header);
    std::getline(csv, first);
    last = first;
    while (std::getline(csv, line)) last = line;
    const auto cell = [&](const std::string& row, const std::string& column) {
        std::istringstream names(header), values(row);
        std::string name, value;
        while (std::getline(names, name, ',') && std::getline(values, value, ','))
            if (name == column) return std::stod(value);
        FAIL("no column " << column);
        return 0.0;
    };
    CHECK(cell(first, "centroid_object0_x") == doctest::Approx(0.15).epsilon(1e-3));
    CHECK(cell(first, "centroid_object0_z") == doctest::Approx(0.1).epsilon(1e-3));
    const double y0 = cell(first, "centroid_object0_y"), y1 = cell(last, "centroid_object0_y");
    CHECK(y0 == doctest::Approx(0.1).epsilon(0.01));
    // Falling freely for 9 steps of 2 ms: g (t1² - t0²) / 2 = 1.6 mm, less what the walls or the
    // fluid took.
    CHECK(y1 < y0 - 0.0005);
    CHECK(y1 > y0 - 0.0025);
    const auto s = read_json(dir + "/summary.json");
    CHECK(s["particles_at_end"]["fluid"] == 125);
    CHECK(s["particles_at_end"]["total"] == s["particles"]["total"]);
}

TEST_CASE("run: frames every 1/fps of simulated time, none with formats []") {
    const std::string dir = out_dir("cadence");
    // dt 0.002, fps 250: frames at t = 0, 0.004, 0.008 over --time 0.008.
    const Result r = run("run " + tiny() + " --time 0.008 --quiet --out " + dir + " --set output.fps=250");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(!contains(r.err, "ms/step"));  // --quiet: no progress, only errors and warnings
    CHECK(!contains(r.err, "output in"));
    CHECK(fs::exists(dir + "/frames/particles_00002.vtu"));
    CHECK(!fs::exists(dir + "/frames/particles_00003.vtu"));
    CHECK(read_json(dir + "/summary.json")["steps"] == 4);

    const std::string none = out_dir("noframes");
    const Result n = run("run " + tiny() + " --steps 1 --quiet --out " + none + " --set 'output.formats=[]'");
    REQUIRE(n.code == 0);
    CHECK(!fs::exists(none + "/frames/particles_00000.vtu"));
    CHECK(fs::exists(none + "/summary.json"));

    // A run without frames into the first run's directory removes its frames (and a killed run's
    // temporaries), so that they do not sit next to a summary that says 0 frames; other files stay.
    write_text(dir + "/frames/particles_00009.vtu.tmp.12345", "partial");
    write_text(dir + "/stats.csv.tmp.12345", "partial");
    write_text(dir + "/frames/notes.txt", "mine");
    const Result again = run("run " + tiny() + " --steps 1 --quiet --out " + dir + " --set 'output.formats=[]'");
    REQUIRE(again.code == 0);
    CHECK(!fs::exists(dir + "/frames/particles_00000.vtu"));
    CHECK(!fs::exists(dir + "/frames/particles.pvd"));
    CHECK(!fs::exists(dir + "/frames/particles_00009.vtu.tmp.12345"));
    CHECK(!fs::exists(dir + "/stats.csv.tmp.12345"));
    CHECK(fs::exists(dir + "/frames/notes.txt"));
    CHECK(read_json(dir + "/summary.json")["frames"] == 0);
}

TEST_CASE("run: plain progress lines when stderr is not a terminal") {
    const std::string dir = out_dir("progress");
    const Result r = run("run " + tiny() + " --steps 10 --out " + dir + " --set 'output.formats=[]'");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.err, "100%"));
    CHECK(contains(r.err, "ms/step"));
    CHECK(!contains(r.err, "\r"));
    // A flag set to false is off, as it reads: --quiet=false keeps the progress lines.
    const Result loud = run("run " + tiny() + " --steps 2 --quiet=false --out " + out_dir("loud") + " --set 'output.formats=[]'");
    REQUIRE(loud.code == 0);
    CHECK(contains(loud.err, "ms/step"));
}

TEST_CASE("a frame reads back with meshio, as VTU and as PLY, the walls once in static_boundary.vtu") {
    // Debian's meshio lives under /usr/bin/python3, which another python3 on PATH may hide.
    std::string python;
    for (const char* candidate : {"/usr/bin/python3", "python3"})
        if (python.empty() && std::system((std::string(candidate) + " -c 'import meshio' >/dev/null 2>&1").c_str()) == 0)
            python = candidate;
    if (python.empty()) {
        MW_SKIP("python3 or meshio is missing (apt install python3-meshio)");
        return;
    }
    const std::string dir = out_dir("meshio");
    REQUIRE(run("run " + tiny() + " --steps 1 --quiet --out " + dir + " --set 'output.formats=[\"vtu\",\"ply\"]'").code == 0);
    const std::string script = scratch_dir() + "/read_frame.py";
    write_text(script,
               "import sys, meshio, numpy\n"
               "m = meshio.read(sys.argv[1] + '/particles_00000.vtu')\n"
               "n = len(m.points)\n"
               "for name in ('velocity', 'density', 'pressure', 'type', 'object', 'id'):\n"
               "    assert name in m.point_data, name\n"
               "    assert len(m.point_data[name]) == n, name\n"
               "assert m.point_data['velocity'].shape == (n, 3)\n"
               "assert (m.point_data['type'].ravel() == 0).sum() == 125 == n, n\n"
               "walls = meshio.read(sys.argv[1] + '/static_boundary.vtu')\n"
               "assert len(walls.points) > 125 and set(walls.point_data['type'].ravel().tolist()) == {1}\n"
               "ids = numpy.concatenate([m.point_data['id'].ravel(), walls.point_data['id'].ravel()])\n"
               "assert sorted(ids.tolist()) == list(range(len(ids))), 'id: each particle once'\n"
               "ply = meshio.read(sys.argv[1] + '/particles_00000.ply')\n"
               "assert numpy.allclose(ply.points, m.points)\n"
               "assert numpy.allclose(numpy.stack([ply.point_data['velocity_' + a] for a in 'xyz'], 1), m.point_data['velocity'])\n"
               "assert (ply.point_data['id'] == m.point_data['id'].ravel()).all()\n"
               "print('ok', n)\n");
    const std::string log = scratch_dir() + "/meshio.log";
    const int status = std::system((python + " '" + script + "' '" + dir + "/frames' >'" + log +
                                    "' 2>&1")
                                       .c_str());
    CAPTURE(slurp(log));
    CHECK(status == 0);
    CHECK(contains(slurp(log), "ok"));
}

TEST_CASE("guards: a blow-up stops the run naming the step, keeping frame 0 and a failed summary") {
    const std::string dir = out_dir("nan");
    // An absurd rest density overflows the float density sum on the first step. No scene value
    // was found that overflows double within a few steps (PCISPH is invariant to the scale of the
    // density), so a double-precision build skips this case; the guard itself is the same code.
    if (sizeof(mw::Real) != 4) {
        MW_SKIP("in a double-precision build no scene value blows it up within 5 steps");
        return;
    }
    const Result r = run("run " + tiny() + " --steps 5 --out " + dir + " --set fluid.rest_density=1e38");
    CAPTURE(r.err);
    REQUIRE(r.code == 4);
    CHECK(contains(r.err, "step"));
    CHECK(contains(r.err, "particle"));
    CHECK(contains(r.err, "kept in"));
    CHECK(fs::exists(dir + "/frames/particles_00000.vtu"));
    CHECK(!fs::exists(dir + "/frames/particles_00001.vtu"));
    const auto s = read_json(dir + "/summary.json");
    CHECK(s["status"] == "failed");
    CHECK(s.contains("error"));
    CHECK(fs::exists(dir + "/stats.csv"));
}

TEST_CASE("guards: a speed whose square overflows stops the run as a failure") {
    // Finite velocity components, |v|² past the scalar type's range: before the guard looked at
    // |v|², the energy would go to inf and the particles leave the grid. (The walls' correction
    // would take the speed away at the wall in the first step: it is turned off here.)
    const std::string speed = sizeof(mw::Real) == 4 ? "1e20" : "1e160";
    const std::string dir = out_dir("overflow");
    const Result r = run("run " + tiny() + " --steps 3 --quiet --out " + dir + " --set 'fluid_blocks.0.velocity=[" +
                         speed + ",0,0]' --set boundary.correction=false");
    CAPTURE(r.err);
    CHECK(r.code == 4);
    CHECK(contains(r.err, "speed overflowed"));
    CHECK(read_json(dir + "/summary.json")["status"] == "failed");
}

namespace {
// The guards' blow-up, as the scene and overrides of a `run`: a 0.5 m column in a 0.7 m tall box
// at a fixed 8 ms, four times the step it holds. PCISPH diverges from step 4 and the walls'
// correction keeps the exploding fluid inside, so nothing is lost.
std::string column_blowing_up() {
    return std::string(MW_SOURCE_DIR) + "/scenes/hydrostatic_column.json" +
           " --set 'domain.max=[0.2,0.7,0.2]' --set 'fluid_blocks.0.max=[0.2,0.5,0.2]'"
           " --set 'output.formats=[]' --set solver.dt=0.008";
}
}  // namespace

TEST_CASE("guards: a blow-up inside the walls stops on solver.max_density_error") {
    // Measured: the peak density error passes 100% (the default) in step 7 and
    // reaches 2,400% by step 25 if the run goes on; never above 5% at 2 ms.
    const std::string column = column_blowing_up();
    SUBCASE("the default limit stops it, naming the step, the error and the key") {
        const std::string dir = out_dir("blowup");
        const Result r = run("run " + column + " --steps 40 --quiet --out " + dir);
        CAPTURE(r.err);
        CHECK(r.code == 4);
        CHECK(contains(r.err, "above its rest density, more than solver.max_density_error 1"));
        CHECK(contains(r.err, "PCISPH diverged"));
        const auto s = read_json(dir + "/summary.json");
        CHECK(s["status"] == "failed");
        CHECK(s["steps"].get<long>() < 40);
        CHECK(s["lost_particles"].get<long>() == 0);
    }
    SUBCASE("a limit it never reaches lets it finish") {
        const std::string dir = out_dir("blowup_allowed");
        const Result r = run("run " + column + " --steps 10 --quiet --out " + dir +
                             " --set solver.max_density_error=1e9");
        CAPTURE(r.err);
        CHECK(r.code == 0);
        // Thrown about by then (26 m/s measured), but not yet past solver.max_speed (next test).
        const auto s = read_json(dir + "/summary.json");
        CHECK(s["speed"]["peak"].get<double>() > 10);
        CHECK(s["speed"]["peak"].get<double>() < s["speed"]["limit"].get<double>());
    }
    SUBCASE("out of range, this limit and the next test's") {
        for (const std::string setting : {"solver.max_density_error=0", "solver.max_speed=-1"}) {
            const Result r = run("run " + column + " --steps 1 --out " + out_dir("blowup_range") + " --set " + setting);
            CAPTURE(r.err);
            CHECK(r.code != 0);
            CHECK(contains(r.err, setting.substr(0, setting.find('=')) + ": must be > 0, got "));
        }
    }
}

TEST_CASE("guards: a run whose fluid is thrown about stops on solver.max_speed") {
    // The same column at 8 ms with the density guard lifted: measured, its fastest
    // particle reaches 26 m/s by step 10, 52 m/s in step 13, 83 m/s in step 19 (and 1e3 m/s and
    // more later, while the CFL step of such a run would shrink towards its floor and the run
    // would grind on). The scene's speed scale is a fall through its 0.7 m: sqrt(2 g 0.7) =
    // 3.706 m/s, so the default limit is 74.1 m/s.
    const std::string column = column_blowing_up(), blowing_up = " --set solver.max_density_error=1e9";
    SUBCASE("the default limit, 20 times the scene's speed scale, stops it and says how it was set") {
        const std::string dir = out_dir("runaway");
        const Result r = run("run " + column + " --steps 40 --quiet --out " + dir + blowing_up);
        CAPTURE(r.err);
        CHECK(r.code == 4);
        CHECK(contains(r.err, "a fluid particle moves at"));
        CHECK(contains(r.err, "more than solver.max_speed 74.12 m/s (20 times the scene's 3.71 m/s"));
        CHECK(contains(r.err, "PCISPH diverged"));
        const auto s = read_json(dir + "/summary.json");
        CHECK(s["status"] == "failed");
        CHECK(s["steps"].get<long>() > 10);
        CHECK(s["steps"].get<long>() < 40);
        CHECK(s["speed"]["limit"].get<double>() == doctest::Approx(20 * std::sqrt(2 * 9.81 * 0.7)).epsilon(1e-6));
        CHECK(s["speed"]["peak"].get<double>() > s["speed"]["limit"].get<double>());
        CHECK(s["scene"]["solver"]["max_speed"].is_null());
    }
    SUBCASE("a limit given in m/s stops it where that limit is passed") {
        const std::string dir = out_dir("runaway_50");
        const Result r = run("run " + column + " --steps 40 --quiet --out " + dir + blowing_up +
                             " --set solver.max_speed=50");
        CAPTURE(r.err);
        CHECK(r.code == 4);
        CHECK(contains(r.err, "more than solver.max_speed 50 m/s;"));
        const auto s = read_json(dir + "/summary.json");
        CHECK(s["speed"]["limit"].get<double>() == 50);
        CHECK(s["speed"]["peak"].get<double>() > 50);
    }
    SUBCASE("no gravity, nothing moving and no emitter: no scale, so no default limit") {
        const std::string dir = out_dir("runaway_none");
        const Result r = run("run " + tiny() + " --steps 2 --quiet --out " + dir + " --set 'gravity=[0,0,0]'");
        CAPTURE(r.err);
        CHECK(r.code == 0);
        CHECK(read_json(dir + "/summary.json")["speed"]["limit"].is_null());
    }
}

namespace {
// stats.csv as rows of named numbers.
std::vector<std::map<std::string, double>> read_stats(const std::string& path) {
    std::istringstream text(slurp(path));
    std::string line;
    std::getline(text, line);
    std::vector<std::string> names;
    std::string cell;
    for (std::istringstream header(line); std::getline(header, cell, ',');) names.push_back(cell);
    std::vector<std::map<std::string, double>> rows;
    while (std::getline(text, line)) {
        std::istringstream values(line);
        std::map<std::string, double> row;
        for (std::size_t c = 0; c < names.size() && std::getline(values, cell, ','); ++c) row[names[c]] = std::stod(cell);
        rows.push_back(row);
    }
    return rows;
}
}  // namespace

TEST_CASE("CFL mode: a step that runs out of iterations above the tolerance is taken again at half the step") {
    // The default dam break at r0 = 0.04 m (6,000 particles), CFL number 0.8 under 10 ms, with
    // PCISPH capped at 10 iterations (a scene that trades iterations for speed). Steps that need
    // more than 10 at their size are taken again at half of it, so every step meets the
    // tolerance. Measured (float, OpenMP): 48 steps to 0.3 s, 4 of them retried;
    // with the retry for divergence only, steps are integrated unconverged (checked: this test
    // then fails).
    const std::string dir = out_dir("cfl_out_of_iterations");
    const Result r = run("run " + std::string(MW_SOURCE_DIR) + "/scenes/dam_break.json --time 0.3 --out " + dir +
                         " --set fluid.spacing=0.04 --set fluid.support_radius=0.08 --set solver.cfl_number=0.8"
                         " --set solver.dt=0.01 --set solver.max_iterations=10 --set 'output.formats=[]'");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.err, "taken again at a smaller dt because PCISPH diverged or ran out of iterations"));
    int retried_after_running_out = 0;
    for (const auto& row : read_stats(dir + "/stats.csv")) {
        CAPTURE(row.at("step"));
        // A retried try that ran out counts its 10 iterations in the step's total.
        retried_after_running_out += row.at("dt_retries") > 0 && row.at("iterations") >= 10;
        CHECK(row.at("unconverged") == 0);
        CHECK(row.at("diverged") == 0);
        CHECK(row.at("density_error_max") <= 0.05 * (1 + 1e-6));  // every step met eta_max
    }
    CHECK(retried_after_running_out >= 1);  // the rule had something to do
    CHECK(read_json(dir + "/summary.json")["unconverged_steps"] == 0);
}

namespace {
// Three steps of the tiny scene at a tolerance that no three iterations reach (min = max = 3,
// so a try cannot diverge either: it always runs out of iterations), with `extra` settings.
struct UnreachableRun {
    Result result;
    std::vector<std::map<std::string, double>> rows;  // stats.csv
    nlohmann::json summary;
};
UnreachableRun run_at_unreachable_tolerance(const std::string& name, const std::string& extra) {
    const std::string dir = out_dir(name);
    UnreachableRun u;
    u.result = run("run " + tiny() + " --steps 3 --out " + dir +
                   " --set solver.eta=1e-6 --set solver.max_iterations=3 --set 'output.formats=[]'" + extra);
    if (u.result.code != 0) return u;
    u.rows = read_stats(dir + "/stats.csv");
    u.summary = read_json(dir + "/summary.json");
    return u;
}
}  // namespace

TEST_CASE("CFL mode: a tolerance no step size reaches does not shrink the step to nothing") {
    // Each step is tried 7 times and integrated unconverged, and since halving did not rescue
    // it, the next step starts again from the CFL bound, not from the last halving (which would
    // divide it by 64 each step).
    const UnreachableRun u =
        run_at_unreachable_tolerance("cfl_unreachable", " --set solver.dt_mode=cfl --set solver.eta_max=0");
    CAPTURE(u.result.err);
    REQUIRE(u.result.code == 0);
    CHECK(contains(u.result.err, "in 3 steps PCISPH ran out of iterations"));
    CHECK(contains(u.result.err, "raise solver.max_iterations"));
    REQUIRE(u.rows.size() == 3);
    for (const auto& row : u.rows) {
        CHECK(row.at("unconverged") == 1);
        CHECK(row.at("dt_retries") == 6);
        CHECK(row.at("iterations") == 7 * 3);
        // The step taken is the sixth halving of a step near the first one's: within a factor 2
        // (the CFL bound moves with the speed), not 64 times smaller.
        CHECK(row.at("dt") > 0.5 * u.rows.front().at("dt"));
    }
}

TEST_CASE("fixed mode: a step that runs out of iterations is counted, and the run warns once") {
    const UnreachableRun u = run_at_unreachable_tolerance("fixed_out_of_iterations", "");
    CAPTURE(u.result.err);
    REQUIRE(u.result.code == 0);
    CHECK(contains(u.result.err, "in 3 steps PCISPH ran out of iterations (solver.max_iterations 3)"));
    CHECK(contains(u.result.err, "dt_mode \"cfl\""));
    REQUIRE(u.rows.size() == 3);
    for (const auto& row : u.rows) {
        CHECK(row.at("unconverged") == 1);
        CHECK(row.at("dt_retries") == 0);  // fixed mode never retries
        CHECK(row.at("iterations") == 3);
    }
    CHECK(u.summary["unconverged_steps"] == 3);
}

TEST_CASE("guards: particles leaving an open domain are counted and reported") {
    const std::string dir = out_dir("lost");
    const Result r = run("run " + tiny() + " --steps 3 --out " + dir +
                         " --set boundary.walls=false --set 'fluid_blocks.0.velocity=[0,-20,0]' --set 'output.formats=[]'");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    const auto s = read_json(dir + "/summary.json");
    CHECK(s["lost_particles"].get<long>() > 0);
    CHECK(contains(r.err, "left the domain"));
}

TEST_CASE("guards: a run that loses more fluid through its walls than boundary.max_lost_fraction stops") {
    // 20 m/s at dt 2 ms is two particle spacings a step: without the walls' velocity-position
    // correction the block punches through the floor. Neighbour lists are pinned: with grid
    // gathers (CUDA's default) the first step's PCISPH diverges to 149% over rest density, so the
    // run stops on solver.max_density_error before any fluid leaves (measured on OpenMP and on an
    // H200 alike).
    const std::string into_floor =
        " --set 'fluid_blocks.0.velocity=[0,-20,0]' --set 'output.formats=[]' --set neighbors.lists=on";
    const std::string through_floor = into_floor + " --set boundary.correction=false";
    SUBCASE("with the walls' correction nothing leaves, and the blow-up stops the run") {
        // Measured: the block's peak density error is 158% in the first step, and its top speed
        // reaches 96 m/s by step 5 if the run goes on: two spacings a step is far past what
        // PCISPH holds, walls or not.
        const std::string dir = out_dir("lost_corrected");
        const Result r = run("run " + tiny() + " --steps 10 --quiet --out " + dir + into_floor);
        CAPTURE(r.err);
        CHECK(r.code == 4);
        CHECK(contains(r.err, "more than solver.max_density_error"));
        const auto s = read_json(dir + "/summary.json");
        CHECK(s["lost_particles"].get<long>() == 0);
        CHECK(s["scene"]["boundary"]["correction"].get<bool>());
    }
    SUBCASE("with walls the default (1%) stops it, naming the step, the count and the key") {
        const std::string dir = out_dir("lost_walls");
        const Result r = run("run " + tiny() + " --steps 10 --quiet --out " + dir + through_floor);
        CAPTURE(r.err);
        CHECK(r.code == 4);
        CHECK(contains(r.err, "of 125 fluid particles"));
        CHECK(contains(r.err, "more than boundary.max_lost_fraction 0.01"));
        const auto s = read_json(dir + "/summary.json");
        CHECK(s["status"] == "failed");
        CHECK(s["steps"].get<long>() < 10);  // stopped at the step that crossed the limit
        CHECK(s["lost_particles"].get<long>() > 125 / 100);
        CHECK(s["scene"]["boundary"]["max_lost_fraction"].get<double>() == doctest::Approx(0.01));
    }
    SUBCASE("a limit of 1 lets the run finish, with the warning") {
        const std::string dir = out_dir("lost_allowed");
        const Result r =
            run("run " + tiny() + " --steps 3 --out " + dir + through_floor + " --set boundary.max_lost_fraction=1");
        CAPTURE(r.err);
        CHECK(r.code == 0);
        CHECK(contains(r.err, "left the domain"));
        CHECK(read_json(dir + "/summary.json")["status"] == "completed");
    }
    SUBCASE("out of range") {
        const Result r = run("run " + tiny() + " --steps 1 --out " + out_dir("lost_range") +
                             " --set boundary.max_lost_fraction=1.5");
        CHECK(r.code != 0);
        CHECK(contains(r.err, "boundary.max_lost_fraction"));
    }
}


TEST_CASE("info: two-way coupling is a stage where fluid meets a moving object, unless the scene turns it off") {
    const std::string scene = tiny_scene_with_box("coupled.json");
    const nlohmann::json on = info_json(scene);
    const std::vector<std::string> with = stages_of(on);
    // In the method's order: after PCISPH, before the solids' step.
    const auto pcisph = std::find(with.begin(), with.end(), "pcisph"), coupling = std::find(with.begin(), with.end(), "coupling"),
               lsm = std::find(with.begin(), with.end(), "lsm");
    REQUIRE(coupling != with.end());
    CHECK(pcisph < coupling);
    CHECK(coupling < lsm);
    CHECK(on["scene"]["coupling"]["two_way"] == true);
    CHECK(contains(run("info " + scene).out, "two-way (coupling.two_way)"));
    CHECK(contains(run("info " + scene + " --set coupling.two_way=false").out, "one-way (coupling.two_way false)"));

    // On by default (the paper's method); a scene may turn it off.
    const nlohmann::json off = info_json(scene, "--set coupling.two_way=false");
    CHECK(off["scene"]["coupling"]["two_way"] == false);
    CHECK(!runs_stage(off, "coupling"));
    CHECK(off["device_bytes"].get<long>() < on["device_bytes"].get<long>());

    // No fluid, nothing to couple: the stage is not run.
    CHECK(!runs_stage(info_json(scene, "--set fluid_blocks=[] --set coupling.two_way=true"), "coupling"));

    const Result bad = run("info " + scene + " --set coupling.two_ways=true");
    CHECK(bad.code != 0);
    CHECK(contains(bad.err, "coupling.two_ways"));
    const Result wrong_type = run("info " + scene + " --set coupling.two_way=1");
    CHECK(wrong_type.code != 0);
    CHECK(contains(wrong_type.err, "coupling.two_way"));
    CHECK(contains(wrong_type.err, "true or false"));
}

TEST_CASE("info: the velocity-position correction against moving objects is a stage after the integration") {
    const std::string scene = tiny_scene_with_box("corrected.json");
    const nlohmann::json on = info_json(scene, "--set coupling.two_way=true --set coupling.correction=true");
    const std::vector<std::string> with = stages_of(on);
    const auto integrate = std::find(with.begin(), with.end(), "integrate"),
               contact = std::find(with.begin(), with.end(), "solid_contact");
    REQUIRE(contact != with.end());
    CHECK(integrate < contact);
    const auto resolved = on["scene"]["coupling"];
    CHECK(resolved["correction"] == true);
    CHECK(resolved["slip"] == 1.0);
    CHECK(contains(run("info " + scene + " --set coupling.two_way=true --set coupling.correction=true").out,
                   "trades momentum with it"));
    // One-way too: the objects are then infinitely heavy, and the fluid takes their velocity.
    const Result one_way = run("info " + scene + " --set coupling.two_way=false");
    REQUIRE(one_way.code == 0);
    CHECK(contains(one_way.out, "takes its velocity"));

    // On by default (the paper's method); a scene may turn it off.
    CHECK(info_json(scene)["scene"]["coupling"]["correction"] == true);
    CHECK(runs_stage(info_json(scene), "solid_contact"));
    const nlohmann::json off = info_json(scene, "--set coupling.correction=false");
    CHECK(off["scene"]["coupling"]["correction"] == false);
    CHECK(!runs_stage(off, "solid_contact"));
    CHECK(contains(run("info " + scene + " --set coupling.correction=false").out,
                   "correction against them off (coupling.correction false)"));

    const Result slip = run("info " + scene + " --set coupling.correction=true --set coupling.slip=1.5");
    CHECK(slip.code != 0);
    CHECK(contains(slip.err, "coupling.slip"));
    const Result wrong_type = run("info " + scene + " --set coupling.correction=1");
    CHECK(wrong_type.code != 0);
    CHECK(contains(wrong_type.err, "coupling.correction"));
}

TEST_CASE("info: PCISPH meets moving objects where they will be, unless coupling.predict_solids is off") {
    const std::string scene = tiny_scene_with_box("lookahead.json");
    // On by default (the paper's method); off, info says what that risks.
    CHECK(info_json(scene)["scene"]["coupling"]["predict_solids"] == true);
    CHECK(contains(run("info " + scene + " --set coupling.predict_solids=false").out,
                   "where they start the step (coupling.predict_solids false)"));
    const Result on = run("info " + scene);
    REQUIRE(on.code == 0);
    CHECK(contains(on.out, "where they will be at the end of the step"));
    const Result wrong_type = run("info " + scene + " --set coupling.predict_solids=1");
    CHECK(wrong_type.code != 0);
    CHECK(contains(wrong_type.err, "coupling.predict_solids"));
}

TEST_CASE("info: rigid objects answer the fluid's pressure inside PCISPH, unless coupling.strong is off") {
    const std::string scene = tiny_scene_with_box("strong.json");  // a rigid box in the fluid
    CHECK(info_json(scene)["scene"]["coupling"]["strong"] == true);
    const Result on = run("info " + scene);
    REQUIRE(on.code == 0);
    CHECK(contains(on.out, "inside every PCISPH iteration (coupling.strong)"));
    CHECK(contains(run("info " + scene + " --set coupling.strong=false").out,
                   "only after PCISPH (coupling.strong false)"));
    const Result wrong_type = run("info " + scene + " --set coupling.strong=1");
    CHECK(wrong_type.code != 0);
    CHECK(contains(wrong_type.err, "coupling.strong"));
}

TEST_CASE("info: rigid objects' surface particles sit inside their faces, unless coupling.surface_inset is off") {
    const std::string scene = tiny_scene_with_box("inset.json");  // a rigid box in the fluid
    CHECK(info_json(scene)["scene"]["coupling"]["surface_inset"] == true);
    const Result on = run("info " + scene);
    REQUIRE(on.code == 0);
    CHECK(contains(on.out, "inside their faces, where the fluid rests as at a wall (coupling.surface_inset)"));
    CHECK(contains(on.out, "stops 0.30 r0 from its surface"));
    const Result off = run("info " + scene + " --set coupling.surface_inset=false");
    CHECK(contains(off.out, "on their faces (coupling.surface_inset false)"));
    CHECK(contains(off.out, "stops 0.45 r0 from its surface"));
    const Result wrong_type = run("info " + scene + " --set coupling.surface_inset=yes");
    CHECK(wrong_type.code != 0);
    CHECK(contains(wrong_type.err, "coupling.surface_inset"));
}

TEST_CASE("info: interface tension is a stage among the non-pressure forces, when an object has it") {
    const std::string scene = tiny_scene_with_box("tension.json");
    const nlohmann::json on = info_json(scene, "--set objects.0.interface_tension=0.2");
    const std::vector<std::string> with = stages_of(on);
    const auto tension = std::find(with.begin(), with.end(), "interface_tension"),
               pcisph = std::find(with.begin(), with.end(), "pcisph");
    REQUIRE(tension != with.end());
    CHECK(tension < pcisph);  // it joins the non-pressure acceleration PCISPH starts from
    CHECK(on["scene"]["objects"][0]["interface_tension"] == 0.2);
    CHECK(contains(run("info " + scene + " --set objects.0.interface_tension=0.2").out, "interface tension (Eq. 9)"));
    // Off by default; and without fluid there is nothing to draw.
    const nlohmann::json off = info_json(scene);
    CHECK(off["scene"]["objects"][0]["interface_tension"] == 0.0);
    CHECK(!runs_stage(off, "interface_tension"));
    CHECK(off["device_bytes"].get<long>() < on["device_bytes"].get<long>());
    CHECK(!runs_stage(info_json(scene, "--set fluid_blocks=[] --set objects.0.interface_tension=0.2"),
                      "interface_tension"));
}
