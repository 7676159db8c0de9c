// Helpers for the command-line tests: run the real `meltwater` binary, capture its output, and
// write small scenes into a scratch directory.
#pragma once
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include "tests/scratch_dir.hpp"

namespace cli_test {

struct Result {
    int code = -1;  // exit status; 128+N for a signal
    std::string out, err;
};

// This program's scratch directory (tests/scratch_dir.hpp).
inline std::string scratch_dir() { return mw_test::scratch_dir("meltwater_cli_test").string(); }

inline std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

inline void write_text(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

// Runs `meltwater <args>` (args are pasted into a shell command line as given).
inline Result run(const std::string& args) {
    static int counter = 0;
    const std::string base = scratch_dir() + "/cmd" + std::to_string(counter++);
    const std::string command =
        std::string("'") + MW_BINARY + "' " + args + " >'" + base + ".out' 2>'" + base + ".err' </dev/null";
    const int status = std::system(command.c_str());
    Result r;
    if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
    else if (status != -1 && WIFSIGNALED(status)) r.code = 128 + WTERMSIG(status);
    r.out = slurp(base + ".out");
    r.err = slurp(base + ".err");
    return r;
}

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

inline int count_lines(const std::string& text) {
    int n = 0;
    for (char c : text) n += c == '\n';
    return n;
}

// A tiny scene (125 fluid particles in a 0.2 m box) with `extra` spliced in as more top-level keys.
inline std::string tiny_scene_text(const std::string& extra = "") {
    return std::string(R"({
  "name": "tiny",
  "domain": { "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] },
  "fluid": { "spacing": 0.02 },
  "solver": { "dt": 0.002 },
  "fluid_blocks": [ { "min": [0, 0, 0], "max": [0.1, 0.1, 0.1] } ])") +
           (extra.empty() ? "" : ",\n  " + extra) + "\n}\n";
}

// Writes a scene file into the scratch directory and returns its path.
inline std::string scene_file(const std::string& name, const std::string& text) {
    const std::string path = scratch_dir() + "/" + name;
    write_text(path, text);
    return path;
}

// A fresh (removed) output directory `name` in the scratch directory.
inline std::string out_dir(const std::string& name) {
    const std::string d = scratch_dir() + "/" + name;
    std::filesystem::remove_all(d);
    return d;
}
inline nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(slurp(path)); }

// stats.csv without its timing columns (ms_*, which differ from run to run; the header names
// them): what the physics computed, step by step.
inline std::string stats_without_timings(const std::string& path) {
    std::istringstream in(slurp(path));
    std::string line, out;
    std::vector<bool> keep;
    while (std::getline(in, line)) {
        std::istringstream cells(line);
        std::string cell;
        for (std::size_t c = 0; std::getline(cells, cell, ','); ++c) {
            if (keep.size() <= c) keep.push_back(cell.rfind("ms_", 0) != 0);
            if (keep[c]) out += cell + ",";
        }
        out += "\n";
    }
    return out;
}

// One line, naming each of `parts`, and exit status `code`.
inline void check_rejected(const Result& r, const std::vector<std::string>& parts, int code = 2) {
    CAPTURE(r.err);
    CHECK(r.code == code);
    CHECK(contains(r.err, "meltwater: "));
    CHECK(count_lines(r.err) == 1);
    for (const auto& p : parts) CHECK(contains(r.err, p));
}

// The tiny scene with a rigid box (0.06 m, 500 kg/m3) beside its fluid, written as `name` (the
// coupling's tests).
inline std::string tiny_scene_with_box(const std::string& name) {
    return scene_file(name, tiny_scene_text(R"("objects": [{"mesh": {"procedural": "box:x=0.06,y=0.06,z=0.06"},
                                          "transform": {"translation": [0.15, 0.1, 0.1]}, "kind": "rigid", "density": 500}])"));
}
// `info SCENE --json OPTIONS`, which must succeed, parsed.
inline nlohmann::json info_json(const std::string& scene, const std::string& options = "") {
    const Result r = run("info " + scene + " --json " + options);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    return nlohmann::json::parse(r.out);
}
// The stages it lists, in order.
inline std::vector<std::string> stages_of(const nlohmann::json& info) {
    std::vector<std::string> names;
    for (const auto& s : info["stages"]) names.push_back(s.get<std::string>());
    return names;
}
inline bool runs_stage(const nlohmann::json& info, const std::string& stage) {
    const std::vector<std::string> names = stages_of(info);
    return std::find(names.begin(), names.end(), stage) != names.end();
}

}  // namespace cli_test
