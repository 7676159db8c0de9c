// The shipped scenes take the same steps as the code they were recorded with. tests/golden/NAME.csv
// holds the physics columns of stats.csv (every column but the stage times) of scenes/NAME.json
// run for the file's row count, with the switches of tests/golden/NAME.set (the coupling and the
// corrections as the recorded run had them); the run here sets the same, explicitly, and must give
// every recorded column, digit for digit. A change that moves a result on purpose records the
// scene again (tests/golden/README.md says how).
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_helpers.hpp"
#include "tests/skip.hpp"

using namespace cli_test;

namespace {

std::vector<std::vector<std::string>> read_csv(const std::string& path) {
    std::vector<std::vector<std::string>> rows;
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ',')) cells.push_back(cell);
        rows.push_back(cells);
    }
    return rows;
}

// The recorded run's switches (NAME.set: one key=value a line), as --set options.
std::string recorded_switches(const std::string& name) {
    std::ifstream in(std::string(MW_SOURCE_DIR) + "/tests/golden/" + name + ".set");
    std::string options, line;
    while (std::getline(in, line))
        if (!line.empty()) options += " --set " + line;
    return options;
}

void check_scene(const std::string& name) {
    const std::string scene = std::string(MW_SOURCE_DIR) + "/scenes/" + name + ".json";
    const std::vector<std::vector<std::string>> golden = read_csv(std::string(MW_SOURCE_DIR) + "/tests/golden/" + name + ".csv");
    REQUIRE(golden.size() > 1);
    if (contains(slurp(scene), "shared/assets/meshes") &&
        !std::filesystem::is_directory(std::string(MW_SHARED_DIR) + "/assets/meshes")) {
        MW_SKIP(name << " needs ../shared/assets/meshes, which is absent");
        return;
    }
    const std::string out = out_dir("same_" + name);
    const Result r = run("run " + scene + " --steps " + std::to_string(golden.size() - 1) +
                         " --set 'output.formats=[]' --threads 2 --quiet --out " + out + recorded_switches(name));
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    const std::vector<std::vector<std::string>> now = read_csv(out + "/stats.csv");
    REQUIRE(now.size() == golden.size());
    // Each recorded column by name (the table may have gained columns since).
    for (std::size_t c = 0; c < golden[0].size(); ++c) {
        const std::string& column = golden[0][c];
        std::size_t at = now[0].size();
        for (std::size_t k = 0; k < now[0].size(); ++k)
            if (now[0][k] == column) at = k;
        CAPTURE(column);
        REQUIRE(at < now[0].size());
        for (std::size_t row = 1; row < golden.size(); ++row) {
            CAPTURE(row);
            REQUIRE(now[row].size() > at);
            REQUIRE(now[row][at] == golden[row][c]);
        }
    }
}

}  // namespace

TEST_CASE("same results: the fluid-only scenes") {
    for (const char* name : {"dam_break", "dam_break_2d", "dam_break_cylinder", "dam_break_paper_kernel", "hydrostatic_column",
                             "splishsplash_block"}) {
        const std::string scene_name = name;
        CAPTURE(scene_name);
        check_scene(name);
    }
}

TEST_CASE("same results: scenes with solids, heat and melting") {
    for (const char* name : {"cantilever", "floating_boxes", "hanging_film", "melting_ice", "thrown_cube", "warm_jelly"}) {
        const std::string scene_name = name;
        CAPTURE(scene_name);
        check_scene(name);
    }
}

TEST_CASE("same results: scenes with the shared meshes") {
    for (const char* name : {"bunny_stream", "elastic_spot_drop", "pinned_bunny"}) {
        const std::string scene_name = name;
        CAPTURE(scene_name);
        check_scene(name);
    }
}
