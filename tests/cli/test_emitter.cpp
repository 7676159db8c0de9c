// Emitters through the command line: the scene keys (docs/scenes.md, "emitters"), what `info`
// says, and what a run writes. The physics is checked in tests/core/test_emitter.cpp.
#include <doctest/doctest.h>

#include <filesystem>

#include "cli_helpers.hpp"

using namespace cli_test;

namespace {
// The tiny scene with a tap over its block: 9 particles a layer (a disc of 1.5 r0), 1 m/s.
std::string tap_scene(const std::string& name, const std::string& tap = "") {
    return scene_file(name, tiny_scene_text(R"("emitters": [ { "name": "tap", "center": [0.15, 0.16, 0.1],
        "direction": [0, -1, 0], "radius": 0.03, "speed": 1.0, "end": 0.1)" + tap + " } ]"));
}
}  // namespace

TEST_CASE("info: an emitter's layers, particles and stage") {
    const std::string scene = tap_scene("emitter_info.json");
    const nlohmann::json info = info_json(scene);
    const std::vector<std::string> stages = stages_of(info);
    REQUIRE(!stages.empty());
    REQUIRE(stages.size() >= 2);
    CHECK(stages[stages.size() - 2] == "emit");  // then the statistics
    CHECK(stages.back() == "statistics");
    // 0.1 s at 1 m/s: a layer every 20 ms, 5 layers of 9 particles (the disc of 1.5 r0).
    REQUIRE(info["emitters"].size() == 1);
    CHECK(info["emitters"][0]["per_layer"] == 9);
    CHECK(info["emitters"][0]["layers"] == 5);
    CHECK(info["particles"]["pending"] == 45);
    CHECK(info["scene"]["emitters"][0]["start"] == 0.0);
    CHECK(info["scene"]["emitters"][0]["temperature"] == 20.0);
    const Result text = run("info " + scene);
    REQUIRE(text.code == 0);
    CHECK(contains(text.out, "pending 45"));
    CHECK(contains(text.out, "tap: 9 particles a layer at 1 m/s, a layer every 0.02 s from t=0 s, 5 layers"));
    // Without an emitter neither the stage nor the pending count shows.
    const Result plain = run("info " + scene_file("emitter_none.json", tiny_scene_text()));
    CHECK(!contains(plain.out, "pending"));
    CHECK(!contains(plain.out, "emitters "));
    CHECK(!runs_stage(info_json(scene_file("emitter_none.json", tiny_scene_text())), "emit"));
}

TEST_CASE("run: emitted particles are counted in stats.csv and summary.json, and frames hold only those released") {
    // Layers at t = 0.005, 0.025, 0.045, ..., frames at 0, 0.02 and 0.04 s: none on a boundary.
    const std::string scene = tap_scene("emitter_run.json", R"(, "start": 0.005)");
    const std::string out = out_dir("emitter_run");
    const Result r = run("run " + scene + " --time 0.05 --quiet --set output.fps=50 --out " + out);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    const std::string stats = slurp(out + "/stats.csv");
    CHECK(contains(stats.substr(0, 400), "unconverged,emitted,ms_"));
    CHECK(contains(stats.substr(0, 400), "ms_emit,ms_statistics,ms_total"));
    const nlohmann::json summary = read_json(out + "/summary.json");
    CHECK(summary["emitted_particles"] == 27);  // three layers of 9 by t = 0.05 s
    CHECK(summary["particles"]["pending"] == 45);  // at the start
    CHECK(!summary.contains("melted_particles"));
    // Frames hold the block and what has been released by their time, no pending particle; the
    // walls are in frames/static_boundary.vtu, once.
    auto points = [&](int frame) {
        char name[64];
        std::snprintf(name, sizeof name, "/frames/particles_%05d.vtu", frame);
        const std::string vtu = slurp(out + name);
        const auto at = vtu.find("NumberOfPoints=\"");
        REQUIRE(at != std::string::npos);
        return std::stol(vtu.substr(at + 16));
    };
    const nlohmann::json counts = info_json(scene)["particles"];
    const long without_pending = counts["total"].get<long>() - 45 - counts["static_boundary"].get<long>();
    REQUIRE(without_pending > 0);
    CHECK(points(0) == without_pending);
    CHECK(points(1) == without_pending + 9);
    CHECK(points(2) == without_pending + 18);
    const std::string plain = out_dir("emitter_plain");
    REQUIRE(run("run " + scene_file("emitter_plain.json", tiny_scene_text()) + " --steps 1 --quiet --out " + plain).code == 0);
    CHECK(!read_json(plain + "/summary.json").contains("emitted_particles"));
    CHECK(!contains(slurp(plain + "/stats.csv").substr(0, 300), "emitted"));
}

TEST_CASE("a scene may have emitters and no fluid block") {
    const std::string scene = scene_file("emitter_only.json", R"({
  "domain": { "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.002 },
  "emitters": [ { "center": [0.1, 0.15, 0.1], "direction": [0, -1, 0], "radius": 0.02, "speed": 0.5, "end": 0.1 } ]
})");
    const std::string out = out_dir("emitter_only");
    const Result r = run("run " + scene + " --time 0.05 --quiet --out " + out);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.out, "density error"));  // the fluid's figures, not "no fluid"
    CHECK(read_json(out + "/summary.json")["emitted_particles"].get<long>() > 0);
    CHECK(info_json(scene)["scene"]["emitters"][0]["name"] == "emitter0");
}

TEST_CASE("an emitter whose disc starts inside the fluid is warned about, by info and run") {
    // The tiny block fills x, y, z < 0.1 m at r0 = 0.02 m, its particles at odd hundredths of a
    // metre. The tap's disc (points r0 apart) centred at (0.06, 0.05, 0.06) lies inside the block,
    // 0.71 r0 from its nearest particles; at y = 0.11 m it is one spacing over the top layer
    // (y = 0.09 m) and 1.22 r0 from it.
    const std::string scene = tap_scene("emitter_inside.json");
    const std::string inside = " --set 'emitters.0.center=[0.06,0.05,0.06]'";
    const nlohmann::json info = info_json(scene, inside);
    REQUIRE(info["warnings"].size() == 1);
    const std::string warning = info["warnings"][0].get<std::string>();
    CHECK(contains(warning, "emitters[0] (tap): its disc starts closer than 0.9 r0 to"));
    CHECK(contains(warning, "the nearest a fluid particle, 0.0141 m from it"));
    CHECK(contains(run("info " + scene + inside).out, "warning     emitters[0] (tap)"));
    const std::string out = out_dir("emitter_inside");
    const Result r = run("run " + scene + inside + " --steps 1 --quiet --out " + out);
    CHECK(r.code == 0);  // a warning: the run goes on
    CHECK(contains(r.err, "meltwater: warning: emitters[0] (tap)"));
    CHECK(read_json(out + "/summary.json")["warnings"].size() == 1);
    // One spacing over the fluid, and the tap of the other tests: no warning.
    CHECK(info_json(scene, " --set 'emitters.0.center=[0.06,0.11,0.06]'")["warnings"].empty());
    CHECK(info_json(scene)["warnings"].empty());
}

TEST_CASE("bad input: emitter keys") {
    const std::string base = R"("center": [0.15, 0.16, 0.1], "direction": [0, -1, 0], "radius": 0.03, "speed": 1.0)";
    auto with = [&](const std::string& name, const std::string& keys) {
        return scene_file(name, tiny_scene_text(R"("emitters": [ { )" + keys + " } ]"));
    };
    check_rejected(run("info " + with("e1.json", R"("direction": [0, -1, 0], "radius": 0.03, "speed": 1.0)")),
                   {"emitters[0].center", "missing"});
    check_rejected(run("info " + with("e2.json", base + R"(, "velocity": 1)")), {"emitters[0].velocity"});
    check_rejected(run("info " + with("e3.json", R"("center": [0.15, 0.16, 0.1], "direction": [0, 0, 0], "radius": 0.03, "speed": 1.0)")),
                   {"emitters[0].direction", "zero"});
    check_rejected(run("info " + with("e4.json", base) + " --set emitters.0.radius=0"), {"emitters[0].radius"});
    check_rejected(run("info " + with("e5.json", base) + " --set emitters.0.speed=-1"), {"emitters[0].speed"});
    check_rejected(run("info " + with("e6.json", base + R"(, "start": 0.5, "end": 0.2)")),
                   {"emitters[0].end", "later than start"});
    // A horizontal disc reaches its radius across x and z (not y): 0.18 + 0.03 passes 0.19.
    check_rejected(run("info " + with("e7.json", base) + " --set emitters.0.center=[0.18,0.16,0.1]"),
                   {"emitters[0]", "inside the domain"});
    CHECK(run("info " + with("e7b.json", base) + " --set emitters.0.center=[0.15,0.19,0.1]").code == 0);
    check_rejected(run("info " + with("e8.json", base) + " --set emitters.0.radius=0.1"), {"emitters[0]", "inside the domain"});
    check_rejected(run("info " + scene_file("e9.json", tiny_scene_text(R"("emitters": [ { "name": "a", )" + base +
                                                                       R"( }, { "name": "a", )" + base + " } ]"))),
                   {"emitters[1].name", "two emitters"});
    std::string many;
    for (int k = 0; k < 17; ++k) many += std::string(k ? ", " : "") + "{ " + base + " }";
    check_rejected(run("info " + scene_file("e10.json", tiny_scene_text("\"emitters\": [ " + many + " ]"))),
                   {"emitters[16]", "at most 16"});
    check_rejected(run("info " + with("e11.json", base) + " --set emitters.0.end=1e9"), {"emitters[0].end"});
}
