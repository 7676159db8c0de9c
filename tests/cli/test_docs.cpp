// The documentation says what the program does: the tables generated from the code (the scene
// keys, the stages of a step) are the ones in the docs, README.md stays short, and no text dates a
// fact by past work (history lives in git).
#include <doctest/doctest.h>

#include <filesystem>
#include <regex>
#include <string>

#include "cli_helpers.hpp"

using namespace cli_test;

namespace {

// The text between <!-- NAME:begin --> and <!-- NAME:end --> in `file` (empty when absent).
std::string generated_block(const std::string& file, const std::string& name) {
    const std::string text = slurp(std::string(MW_SOURCE_DIR) + "/" + file);
    const std::string begin = "<!-- " + name + ":begin -->\n", end = "<!-- " + name + ":end -->";
    const std::size_t a = text.find(begin), b = text.find(end);
    if (a == std::string::npos || b == std::string::npos || b < a) return "";
    return text.substr(a + begin.size(), b - a - begin.size());
}

}  // namespace

TEST_CASE("docs: the scene keys' table in docs/scenes.md is the one the code declares") {
    const Result r = run("schema --markdown");
    REQUIRE(r.code == 0);
    REQUIRE(contains(r.out, "| `fluid.spacing` |"));
    // On a difference: meltwater schema --markdown, pasted between the markers.
    CHECK(generated_block("docs/scenes.md", "schema") == r.out);
}

TEST_CASE("docs: the stage table in docs/architecture.md is the step plan's") {
    const Result r = run("schema --stages --markdown");
    REQUIRE(r.code == 0);
    REQUIRE(contains(r.out, "| `pcisph` |"));
    CHECK(generated_block("docs/architecture.md", "stages") == r.out);
}

TEST_CASE("docs: README.md is at most 200 lines") {
    const std::string readme = slurp(std::string(MW_SOURCE_DIR) + "/README.md");
    REQUIRE(!readme.empty());
    CHECK(count_lines(readme) <= 200);
}

TEST_CASE("no text in the code, docs, scenes or messages dates a fact by past work") {
    // The phrases that date a fact: "(in) the twelfth session", "since the ... change", "before
    // the ... rewrite", "until the ... session". Measurement reports (bench/results) keep their dates.
    const std::regex dated(
        R"(\b((first|second|third|[a-z]+(th|st|nd|rd)|[0-9]+(th|st|nd|rd)) sessions?|(since|before|until) the [a-z-]+ (session|change|rewrite|fix))\b)",
        std::regex::icase);
    long files = 0;
    for (const char* folder : {"algorithms", "apps", "backend", "common", "docs", "sampling", "scenes", "simulation",
                               "surface", "tests", "bench"}) {
        for (const auto& entry : std::filesystem::recursive_directory_iterator(std::string(MW_SOURCE_DIR) + "/" + folder)) {
            const std::string path = entry.path().string();
            if (!entry.is_regular_file() || path.find("/bench/results/") != std::string::npos ||
                path.find("/tests/golden/") != std::string::npos || path.find("test_docs.cpp") != std::string::npos)
                continue;
            ++files;
            const std::string text = slurp(path);
            std::smatch m;
            CAPTURE(path);
            if (std::regex_search(text, m, dated)) CHECK_MESSAGE(false, "dated by past work: \"" << m.str() << "\"");
        }
    }
    const std::string readme = slurp(std::string(MW_SOURCE_DIR) + "/README.md");
    std::smatch m;
    if (std::regex_search(readme, m, dated)) CHECK_MESSAGE(false, "README.md: \"" << m.str() << "\"");
    CHECK(files > 100);
}
