// Heat conduction through the command line: the scene keys (docs/heat.md), the stage in `info`,
// and the temperature in the frames. The physics is checked in tests/core/test_heat.cpp.
#include <doctest/doctest.h>

#include <cmath>

#include "cli_helpers.hpp"

using namespace cli_test;

namespace {
// The tiny scene with its box as a hot elastic object, heat on or off.
std::string heated_box_options(bool heat) {
    return std::string(" --set heat.enabled=") + (heat ? "true" : "false") +
           " --set objects.0.temperature=80 --set fluid.temperature=10 --set objects.0.thermal_diffusivity=0.001"
           " --set fluid.thermal_diffusivity=0.0005";
}
}  // namespace

TEST_CASE("info: heat conduction is a stage after PCISPH when the scene asks, and costs nothing otherwise") {
    const std::string scene = tiny_scene_with_box("heat.json");
    const nlohmann::json on = info_json(scene, heated_box_options(true));
    const std::vector<std::string> with = stages_of(on);
    const auto heat = std::find(with.begin(), with.end(), "heat"), pcisph = std::find(with.begin(), with.end(), "pcisph");
    REQUIRE(heat != with.end());
    CHECK(heat > pcisph);  // the step's length is settled by then
    CHECK(on["scene"]["heat"]["enabled"] == true);
    CHECK(on["heat_substeps_needed"].get<int>() >= 1);
    CHECK(on["scene"]["objects"][0]["temperature"] == 80.0);
    CHECK(on["scene"]["fluid_blocks"][0]["temperature"] == 10.0);  // fluid.temperature is the blocks' default
    CHECK(contains(run("info " + scene + heated_box_options(true)).out, "conduction on (heat.enabled)"));
    const nlohmann::json off = info_json(scene, heated_box_options(false));
    CHECK(!runs_stage(off, "heat"));
    CHECK(off["device_bytes"].get<long>() < on["device_bytes"].get<long>());
    CHECK(!contains(run("info " + scene).out, "conduction on"));
    // A step whose Fourier number needs more sub-steps than heat.max_substeps allows is warned about.
    const nlohmann::json capped =
        info_json(scene, heated_box_options(true) + " --set heat.max_substeps=1 --set fluid.thermal_diffusivity=0.5");
    REQUIRE(capped["warnings"].size() == 1);
    CHECK(capped["heat_substeps_needed"].get<int>() > 1);
    CHECK(contains(capped["warnings"][0].get<std::string>(), "heat.max_substeps (1)"));
    CHECK(info_json(scene, heated_box_options(true))["warnings"].empty());
}

TEST_CASE("run: frames carry each particle's temperature when heat conduction is on") {
    const std::string scene = tiny_scene_with_box("heat_run.json");
    const std::string hot = out_dir("heat_on"), plain = out_dir("heat_off");
    const Result r = run("run " + scene + " --steps 3 --quiet --out " + hot + heated_box_options(true));
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(slurp(hot + "/frames/particles_00000.vtu"), "Name=\"temperature\""));
    const std::string header = slurp(hot + "/stats.csv").substr(0, 400);
    CHECK(contains(header, "ms_heat"));
    CHECK(contains(header, "unconverged,centroid_object0_x,centroid_object0_y,centroid_object0_z,heat_substeps,"
                           "heat_content,solid_max_speed,solid_kinetic_energy,ms_"));
    const nlohmann::json summary = read_json(hot + "/summary.json");
    REQUIRE(summary.contains("heat_content"));
    CHECK(std::fabs(summary["heat_content"]["relative_change"].get<double>()) < 1e-5);
    CHECK(summary["heat_content"]["at_end"].get<double>() > 0);
    REQUIRE(run("run " + scene + " --steps 1 --quiet --out " + plain).code == 0);
    CHECK(!contains(slurp(plain + "/frames/particles_00000.vtu"), "temperature"));
    CHECK(!contains(slurp(plain + "/stats.csv").substr(0, 400), "heat_content"));
    CHECK(!read_json(plain + "/summary.json").contains("heat_content"));
}

TEST_CASE("bad input: heat keys") {
    const std::string scene = tiny_scene_with_box("heat_bad.json");
    check_rejected(run("info " + scene + " --set heat.max_substeps=0"), {"heat.max_substeps", "[1, 1000]"});
    check_rejected(run("info " + scene + " --set heat.substeps=4"), {"heat.substeps", "no such key"});
    check_rejected(run("info " + scene + " --set fluid.temperature=-300"), {"fluid.temperature", "-273.15"});
    check_rejected(run("info " + scene + " --set fluid_blocks.0.temperature=hot"), {"fluid_blocks[0].temperature"});
    check_rejected(run("info " + scene + " --set objects.0.thermal_diffusivity=-1"), {"objects[0].thermal_diffusivity"});
    check_rejected(run("info " + scene + " --set fluid.heat_capacity=0"), {"fluid.heat_capacity", "> 0"});
    check_rejected(run("info " + scene + " --set objects.0.heat_capacity=-5"), {"objects[0].heat_capacity"});
}
