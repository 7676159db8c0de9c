// `meltwater run --checkpoint` and `--resume` end to end: a run stopped half way and resumed
// writes what the whole run writes, byte for byte; a bad checkpoint or a bad combination of
// options is one clear line and a non-zero exit.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_helpers.hpp"

using namespace cli_test;
namespace fs = std::filesystem;

namespace {
// scenes/floating_boxes.json at twice its spacing (an elastic and a rigid box in a pool, two-way
// coupling and the correction, CFL steps): every kind of state a checkpoint carries, in 0.2 s a run.
std::string floating_boxes() {
    return std::string(MW_SOURCE_DIR) +
           "/scenes/floating_boxes.json --set fluid.spacing=0.04 --set fluid.support_radius=0.08 "
           "--set output.fps=200 --threads 2 --quiet";
}
}  // namespace

TEST_CASE("checkpoint: a run stopped half way and resumed ends byte for byte as the whole run") {
    const std::string whole = out_dir("ckpt_whole"), halves = out_dir("ckpt_halves");
    Result r = run("run " + floating_boxes() + " --steps 60 --checkpoint --out " + whole);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    r = run("run " + floating_boxes() + " --steps 30 --checkpoint --out " + halves);
    REQUIRE(r.code == 0);
    CHECK(contains(r.out, "checkpoint.mwc"));
    CHECK(read_json(halves + "/summary.json")["checkpoint"]["step"] == 30);
    // The frames the first half wrote after t = 0.12 s are not its concern: the resumed run
    // rewrites them. --out defaults to the checkpoint's directory.
    r = run("run --resume " + halves + "/checkpoint.mwc --steps 30 --checkpoint --threads 1 --quiet");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    // The state, the frame clock and the scene: the checkpoints are the same file.
    CHECK(slurp(whole + "/checkpoint.mwc") == slurp(halves + "/checkpoint.mwc"));
    // stats.csv continues from the checkpoint's step; its physics columns match the whole run's.
    CHECK(stats_without_timings(whole + "/stats.csv") == stats_without_timings(halves + "/stats.csv"));
    // The frames: as many, the collection the same, the last one the same bytes.
    std::size_t whole_frames = 0, halves_frames = 0;
    for (const auto& e : fs::directory_iterator(whole + "/frames")) whole_frames += e.is_regular_file();
    for (const auto& e : fs::directory_iterator(halves + "/frames")) halves_frames += e.is_regular_file();
    CHECK(whole_frames == halves_frames);
    CHECK(slurp(whole + "/frames/particles.pvd") == slurp(halves + "/frames/particles.pvd"));
    const std::string last = "/frames/particles_00048.vtu";
    REQUIRE(fs::exists(whole + last));
    CHECK(slurp(whole + last) == slurp(halves + last));
    // The resumed run's summary covers its own 30 steps, and says where it started.
    const auto summary = read_json(halves + "/summary.json");
    CHECK(summary["steps"] == 30);
    CHECK(summary["resumed_from"]["step"] == 30);
    CHECK(summary["checkpoint"]["step"] == 60);
}

TEST_CASE("checkpoint: resumed into another directory, frames are numbered on, and --checkpoint-every") {
    const std::string first = out_dir("ckpt_every"), second = out_dir("ckpt_elsewhere");
    Result r = run("run " + floating_boxes() + " --steps 25 --checkpoint-every 10 --out " + first);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    // Every 10 steps and at the end: the last is the one kept.
    CHECK(read_json(first + "/summary.json")["checkpoint"]["step"] == 25);
    r = run("run --resume " + first + "/checkpoint.mwc --time 0.12 --out " + second + " --quiet");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    // Only this run's frames there, numbered after the first run's 21 (t = 0 to 0.1 s at 200 fps).
    CHECK_FALSE(fs::exists(second + "/frames/particles_00000.vtu"));
    CHECK(fs::exists(second + "/frames/particles_00021.vtu"));
    CHECK_FALSE(fs::exists(second + "/checkpoint.mwc"));  // not asked for
    const auto summary = read_json(second + "/summary.json");
    CHECK(summary["simulated_time"].get<double>() >= 0.12 - 1e-6);
    CHECK(summary["resumed_from"]["step"] == 25);
    // The original directory is left as it was.
    CHECK(read_json(first + "/summary.json")["steps"] == 25);
}

TEST_CASE("bad input: checkpoints") {
    const std::string dir = out_dir("ckpt_bad");
    Result r = run("run " + floating_boxes() + " --steps 2 --checkpoint --out " + dir);
    REQUIRE(r.code == 0);
    const std::string good = dir + "/checkpoint.mwc";
    const std::string bytes = slurp(good);
    check_rejected(run("run --resume " + dir + "/none.mwc"), {"none.mwc", "does not exist"});
    check_rejected(run("run --resume " + dir), {"is a directory"});
    write_text(dir + "/text.mwc", "{\"not\": \"a checkpoint\"}\n");
    check_rejected(run("run --resume " + dir + "/text.mwc"), {"text.mwc", "not a Meltwater checkpoint"});
    write_text(dir + "/short.mwc", bytes.substr(0, bytes.size() / 2));
    check_rejected(run("run --resume " + dir + "/short.mwc"), {"short.mwc", "truncated"});
    std::string damaged = bytes;
    damaged[damaged.size() - 100] ^= 1;
    write_text(dir + "/damaged.mwc", damaged);
    check_rejected(run("run --resume " + dir + "/damaged.mwc"), {"damaged.mwc", "checksum"});
    std::string later = bytes;
    later.replace(later.find(" 1\n"), 3, " 9\n");
    write_text(dir + "/later.mwc", later);
    check_rejected(run("run --resume " + dir + "/later.mwc"), {"format version 9"});
    check_rejected(run("run " + std::string(MW_SOURCE_DIR) + "/scenes/floating_boxes.json --resume " + good),
                   {"--resume", "no SCENE"});
    check_rejected(run("run --resume " + good + " --set solver.dt=0.001"), {"--resume", "no --set"});
    check_rejected(run("run --resume " + good + " --time 0.001"), {"already at the end time"});
    check_rejected(run("run --checkpoint-every 0"), {"--checkpoint-every"});
    // None of these touched the checkpoint's directory.
    CHECK(slurp(good) == bytes);
}
