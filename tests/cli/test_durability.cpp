// What a run leaves on disk when it is killed at any moment, or after a power cut: stats.csv that
// reaches the last checkpoint and a resume that continues it row for row, no earlier run's records
// beside a new run's frames, every output flushed before its rename, and checkpoints whose header
// agrees with their state.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "apps/checkpoint_file.hpp"
#include "cli_helpers.hpp"
#include "tests/skip.hpp"

using namespace cli_test;
namespace fs = std::filesystem;

namespace {

// scenes/floating_boxes.json at twice its spacing: a run of a few hundred steps that writes
// frames, checkpoints and stats.csv while the test watches its directory.
std::vector<std::string> floating_boxes_args(const std::string& out, long steps) {
    return {"run",      std::string(MW_SOURCE_DIR) + "/scenes/floating_boxes.json",
            "--set",    "fluid.spacing=0.04",
            "--set",    "fluid.support_radius=0.08",
            "--set",    "output.fps=200",
            "--steps",  std::to_string(steps),
            "--threads", "2",
            "--quiet",  "--out",
            out};
}

// The same scene as one command line for run(): `extra` options, then --out DIR.
std::string floating_boxes_command(const std::string& extra, const std::string& out) {
    return "run " + std::string(MW_SOURCE_DIR) +
           "/scenes/floating_boxes.json --set fluid.spacing=0.04 --set fluid.support_radius=0.08 " + extra + " --out " + out;
}

// Starts `meltwater ARGS` in the background, its output discarded; returns its process id.
pid_t start(const std::vector<std::string>& args) {
    const pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        std::vector<char*> argv{const_cast<char*>(MW_BINARY)};
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr)) ::_exit(126);
        ::execv(MW_BINARY, argv.data());
        ::_exit(127);
    }
    return pid;
}

// Waits (up to a minute) for `ready`, then kills the process with SIGKILL: no handler runs, as
// after a crash or an out-of-memory kill. Returns whether `ready` was seen before the process ended.
template <class Ready>
bool kill_when(pid_t pid, Ready&& ready) {
    bool seen = false;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
        if (ready()) {
            seen = true;
            break;
        }
        if (::waitpid(pid, &status, WNOHANG) == pid) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    return seen;
}

// The steps of stats.csv's rows, in order.
std::vector<long> stats_steps(const std::string& path) {
    std::istringstream in(slurp(path));
    std::string line;
    std::vector<long> steps;
    std::getline(in, line);  // the header
    while (std::getline(in, line)) steps.push_back(std::strtol(line.c_str(), nullptr, 10));
    return steps;
}

// Whether `steps` is first, first+1, ..., last.
bool runs_from_to(const std::vector<long>& steps, long first, long last) {
    if (steps.size() != static_cast<std::size_t>(last - first + 1)) return false;
    for (std::size_t k = 0; k < steps.size(); ++k)
        if (steps[k] != first + long(k)) return false;
    return true;
}

}  // namespace

TEST_CASE("durability: killed after a checkpoint, stats.csv reaches it, and the resumed run continues it row for row") {
    const std::string dir = out_dir("durable_kill");
    const std::string checkpoint = dir + "/" + mw::kCheckpointFileName;
    // Killed at once when the first checkpoint (step 20) is on disk: long before stats.csv's
    // periodic rewrite, so only the write that goes with the checkpoint can have made it.
    std::vector<std::string> args = floating_boxes_args(dir, 400);
    args.insert(args.end(), {"--checkpoint-every", "20"});
    REQUIRE(kill_when(start(args), [&] { return fs::exists(checkpoint); }));
    const long step = mw::read_checkpoint(checkpoint).step;
    CHECK(step % 20 == 0);
    REQUIRE(fs::exists(dir + "/stats.csv"));
    const std::vector<long> before = stats_steps(dir + "/stats.csv");
    REQUIRE_FALSE(before.empty());
    CHECK(before.front() == 1);
    CHECK(before.back() >= step);
    // Resumed in the same directory for 5 steps: rows 1 to step + 5, none missing, none twice.
    const Result r = run("run --resume " + checkpoint + " --steps 5 --quiet");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK_FALSE(contains(r.err, "warning"));
    CHECK(runs_from_to(stats_steps(dir + "/stats.csv"), 1, step + 5));
}

TEST_CASE("durability: a resume whose stats.csv stops short of the checkpoint says so and starts the table after it") {
    const std::string dir = out_dir("durable_short_stats");
    Result r = run(floating_boxes_command("--steps 12 --checkpoint --threads 2 --quiet", dir));
    REQUIRE(r.code == 0);
    // Rows 1 to 7 only, as a stats.csv from another time would hold.
    std::istringstream in(slurp(dir + "/stats.csv"));
    std::string line, kept;
    for (int k = 0; k < 8 && std::getline(in, line); ++k) kept += line + "\n";
    write_text(dir + "/stats.csv", kept);
    r = run("run --resume " + dir + "/checkpoint.mwc --steps 3 --quiet");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.err, "stats.csv ends at step 7, before the checkpoint's step 12"));
    CHECK(runs_from_to(stats_steps(dir + "/stats.csv"), 13, 15));
    const auto warnings = read_json(dir + "/summary.json")["warnings"];
    REQUIRE(warnings.size() == 1);
    CHECK(contains(warnings[0].get<std::string>(), "starts after the checkpoint, at step 13"));
    // A gap inside the rows is refused the same way.
    r = run(floating_boxes_command("--steps 12 --checkpoint --threads 2 --quiet", dir));
    REQUIRE(r.code == 0);
    std::istringstream rows(slurp(dir + "/stats.csv"));
    std::string gapped;
    for (int k = 0; std::getline(rows, line); ++k)
        if (k != 5) gapped += line + "\n";
    write_text(dir + "/stats.csv", gapped);
    r = run("run --resume " + dir + "/checkpoint.mwc --steps 1 --quiet");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.err, "stats.csv jumps from step 4 to step 6"));
    CHECK(runs_from_to(stats_steps(dir + "/stats.csv"), 13, 13));
}

TEST_CASE("durability: a fresh run in a reused directory removes the earlier run's records before its first frame") {
    const std::string dir = out_dir("durable_reused");
    Result r = run(floating_boxes_command("--steps 3 --checkpoint --threads 2 --quiet", dir));
    REQUIRE(r.code == 0);
    REQUIRE(read_json(dir + "/summary.json")["status"] == "completed");
    // The new run is killed as soon as its own frame 0 is in place (the earlier one removed here,
    // so that its appearing marks the new run's).
    REQUIRE(fs::remove(dir + "/frames/particles_00000.vtu"));
    REQUIRE(kill_when(start(floating_boxes_args(dir, 400)),
                      [&] { return fs::exists(dir + "/frames/particles_00000.vtu"); }));
    CHECK_FALSE(fs::exists(dir + "/summary.json"));
    CHECK_FALSE(fs::exists(dir + "/" + mw::kCheckpointFileName));
    // Run to its end, the fresh run says what it removed.
    r = run(floating_boxes_command("--steps 2 --threads 2", dir));
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.err, "removed an earlier run's outputs from"));
}

TEST_CASE("durability: a checkpoint whose header disagrees with its state is refused, whatever its checksum") {
    const std::string dir = out_dir("durable_header");
    const Result r = run(floating_boxes_command("--set output.fps=200 --steps 12 --checkpoint --threads 2 --quiet", dir));
    REQUIRE(r.code == 0);
    const mw::Checkpoint good = mw::read_checkpoint(dir + "/checkpoint.mwc");
    // Each edit written back through the writer, so its checksum is valid.
    auto edited = [&](const std::string& name, auto&& edit) {
        mw::Checkpoint c = good;
        edit(c);
        const std::string path = dir + "/" + name;
        mw::write_checkpoint(path, c);
        return path;
    };
    check_rejected(run("run --resume " + edited("step.mwc", [](mw::Checkpoint& c) { c.step += 1000; }) + " --steps 1"),
                   {"step.mwc", "inconsistent", "header says step 1012", "its state step 12"});
    check_rejected(run("run --resume " + edited("time.mwc", [](mw::Checkpoint& c) { c.time *= 2; }) + " --steps 1"),
                   {"time.mwc", "inconsistent"});
    check_rejected(run("run --resume " +
                       edited("frames.mwc", [](mw::Checkpoint& c) { c.frame_times.back() = c.time + 1; }) + " --steps 1"),
                   {"frames.mwc", "inconsistent", "after the state's t"});
    check_rejected(run("run --resume " +
                       edited("due.mwc", [](mw::Checkpoint& c) { c.next_frame_time = -1; }) + " --steps 1"),
                   {"due.mwc", "inconsistent", "next frame"});
    // The same file unedited, written by the same writer, is taken.
    const Result resumed = run("run --resume " + edited("same.mwc", [](mw::Checkpoint&) {}) +
                               " --steps 1 --quiet --out " + out_dir("durable_header_same"));
    CAPTURE(resumed.err);
    CHECK(resumed.code == 0);
}

TEST_CASE("durability: every output is flushed to disk before its rename, and its directory after") {
    if (std::system("command -v strace >/dev/null 2>&1") != 0) {
        MW_SKIP("strace is not installed (scripts/setup.sh installs it)");
        return;
    }
    const std::string dir = fs::weakly_canonical(out_dir("durable_sync")).string();
    const std::string trace = scratch_dir() + "/durable_sync.strace";
    // LeakSanitizer (in `make sanitize`) cannot run under ptrace: off for this one run.
    const std::string command = "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" strace -f -y -qq -o '" + trace +
                                "' -e trace=fsync,fdatasync,rename,renameat,renameat2 '" + MW_BINARY + "' run " +
                                std::string(MW_SOURCE_DIR) +
                                "/scenes/floating_boxes.json --set fluid.spacing=0.04 --set "
                                "fluid.support_radius=0.08 --set output.fps=200 --steps 12 --checkpoint-every 5 "
                                "--threads 2 --quiet --out '" +
                                dir + "' >/dev/null 2>'" + trace + ".err'";
    const int status = std::system(command.c_str());
    if (status != 0 && contains(slurp(trace + ".err"), "ptrace")) {
        MW_SKIP("strace cannot trace here: " << slurp(trace + ".err"));
        return;
    }
    REQUIRE(status == 0);
    // Lines such as   123 fsync(3</dir/stats.csv.tmp.123>) = 0   and
    //                 123 rename("/dir/stats.csv.tmp.123", "/dir/stats.csv") = 0
    std::istringstream lines(slurp(trace));
    std::string line;
    std::map<std::string, bool> synced;  // paths fsync'd so far
    std::string renamed_to;              // the last rename's target, awaiting its directory's fsync
    int renames = 0, directories_synced = 0;
    std::map<std::string, int> renamed;  // how often each name was renamed into place
    while (std::getline(lines, line)) {
        const std::size_t fsync_at = line.find("fsync(");
        if (fsync_at != std::string::npos) {
            const std::size_t open = line.find('<', fsync_at), close = line.find('>', open);
            REQUIRE(open != std::string::npos);
            const std::string path = line.substr(open + 1, close - open - 1);
            synced[path] = true;
            if (!renamed_to.empty() && path == fs::path(renamed_to).parent_path().string()) {
                ++directories_synced;
                renamed_to.clear();
            }
            continue;
        }
        const std::size_t first = line.find('"');
        if (line.find("rename") == std::string::npos || first == std::string::npos) continue;
        const std::size_t first_end = line.find('"', first + 1);
        const std::size_t second = line.find('"', first_end + 1), second_end = line.find('"', second + 1);
        const std::string from = line.substr(first + 1, first_end - first - 1);
        const std::string to = line.substr(second + 1, second_end - second - 1);
        INFO(line);
        CHECK(renamed_to.empty());  // the previous rename's directory was flushed before this one
        CHECK(synced[fs::weakly_canonical(fs::path(to).parent_path()).string() + "/" + fs::path(from).filename().string()]);
        renamed_to = fs::weakly_canonical(fs::path(to)).string();
        ++renamed[fs::path(to).filename().string()];
        ++renames;
    }
    CHECK(renamed_to.empty());
    CHECK(directories_synced == renames);
    // Frames, the collection, stats.csv (with each checkpoint and at the end), the checkpoints
    // and summary.json were all seen.
    CHECK(renamed["checkpoint.mwc"] == 3);  // steps 5, 10 and at the end, 12
    CHECK(renamed["stats.csv"] >= 3);
    CHECK(renamed["summary.json"] == 1);
    CHECK(renamed["particles_00001.vtu"] == 1);
    CHECK(renamed["particles.pvd"] >= 1);
}
