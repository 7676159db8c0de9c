// Melting through the command line: the scene keys (docs/melting.md), the stage in `info`, and
// what a run reports. The physics is checked in tests/core/test_melting.cpp.
#include <doctest/doctest.h>

#include <filesystem>

#include "cli_helpers.hpp"

using namespace cli_test;

namespace {
// The tiny scene's box as an elastic object 30 K above its melting point, in water at 40 °C.
const std::string kMelting =
    " --set heat.enabled=true --set objects.0.kind=elastic --set objects.0.temperature=30"
    " --set objects.0.melting_point=0 --set fluid.temperature=40";
}  // namespace

TEST_CASE("info: melting is the last stage of physics when an object has a melting point") {
    const std::string scene = tiny_scene_with_box("melting.json");
    const nlohmann::json on = info_json(scene, kMelting);
    const std::vector<std::string> stages = stages_of(on);
    REQUIRE(!stages.empty());
    REQUIRE(stages.size() >= 2);
    CHECK(stages[stages.size() - 2] == "melting");  // then the statistics
    CHECK(stages.back() == "statistics");
    CHECK(on["scene"]["objects"][0]["melting_point"] == 0.0);
    CHECK(on["scene"]["objects"][0]["latent_heat"] == 0.0);
    CHECK(!runs_stage(info_json(scene, " --set heat.enabled=true --set objects.0.kind=elastic"), "melting"));
}

TEST_CASE("run: melted particles are counted in stats.csv and summary.json, and become fluid in the frames") {
    const std::string scene = tiny_scene_with_box("melting_run.json");
    const std::string out = out_dir("melting_on");
    const Result r = run("run " + scene + " --steps 2 --quiet --out " + out + kMelting);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    const std::string stats = slurp(out + "/stats.csv");
    CHECK(contains(stats.substr(0, 400), "heat_content,melted,solid_max_speed,solid_kinetic_energy,ms_"));
    CHECK(contains(stats.substr(0, 400), "ms_melting"));
    const nlohmann::json summary = read_json(out + "/summary.json");
    REQUIRE(summary.contains("melted_particles"));
    // Every particle of the box starts 30 K above its melting point: its surface melts at once.
    CHECK(summary["melted_particles"].get<long>() > 0);
    CHECK(contains(slurp(out + "/frames/particles_00000.vtu"), "Name=\"temperature\""));
    CHECK(!std::filesystem::exists(out + "/frames/object_object0_00000.obj"));  // no mesh follows a melting object
    const std::string plain = out_dir("melting_off");
    REQUIRE(run("run " + scene + " --steps 1 --quiet --out " + plain + " --set heat.enabled=true").code == 0);
    CHECK(!read_json(plain + "/summary.json").contains("melted_particles"));
}

TEST_CASE("bad input: melting keys") {
    const std::string scene = tiny_scene_with_box("melting_bad.json");
    check_rejected(run("info " + scene + " --set objects.0.kind=elastic --set objects.0.melting_point=0"),
                   {"objects[0].melting_point", "heat.enabled"});
    check_rejected(run("info " + scene + " --set heat.enabled=true --set objects.0.melting_point=0"),
                   {"objects[0].melting_point", "elastic objects", "rigid"});
    check_rejected(run("info " + scene + " --set heat.enabled=true --set objects.0.kind=elastic"
                                         " --set objects.0.latent_heat=1000"),
                   {"objects[0].latent_heat", "melting_point"});
    check_rejected(run("info " + scene + kMelting + " --set objects.0.latent_heat=-1"), {"objects[0].latent_heat"});
    check_rejected(run("info " + scene + kMelting + " --set objects.0.melting_point=-400"),
                   {"objects[0].melting_point", "-273.15"});
}
