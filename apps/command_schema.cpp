// `meltwater schema`: every scene key with its type, default, allowed values, unit and meaning,
// from the modules' key tables (simulation/parameters.hpp). `--markdown` prints the reference
// table of docs/scenes.md, which a test keeps equal to it; `--stages` the time step's stages
// (algorithms/step_plan.hpp), the table of docs/architecture.md.
#include <cstdio>
#include <string>

#include "algorithms/step_plan.hpp"
#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "apps/scene.hpp"

namespace mw {

namespace {

// A table cell: `|` escaped, so that a doc line cannot break the row.
std::string cell(const std::string& text) {
    std::string out;
    for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
}
std::string code(const std::string& text) { return text.empty() ? "" : "`" + text + "`"; }

void print_keys_markdown() {
    std::printf("| key | type | default | allowed | unit | meaning |\n| --- | --- | --- | --- | --- | --- |\n");
    for (const ParamDoc& d : scene_schema())
        std::printf("| %s | %s | %s | %s | %s | %s |\n", code(d.path).c_str(), d.type.c_str(),
                    cell(d.default_text).c_str(), cell(d.allowed).c_str(), cell(d.unit).c_str(), cell(d.doc).c_str());
}

void print_stages_markdown() {
    std::printf("| stage | module | runs | does |\n| --- | --- | --- | --- |\n");
    for (const StageInfo& s : kStepStages)
        std::printf("| `%s` | %s | %s | %s |\n", s.name, s.module, cell(s.runs).c_str(), cell(s.does).c_str());
}

}  // namespace

int command_schema(int argc, char** argv) {
    cxxopts::Options options("meltwater schema",
                             "Every scene key with its type, default, allowed values, unit and meaning (docs/scenes.md),\n"
                             "or the stages of a time step in their order.");
    options.add_options()("markdown", "print a Markdown table")("json", "print one JSON array")(
        "stages", "the stages of a time step instead of the keys")("h,help", "show this help");
    const cxxopts::ParseResult args = parse_options(options, argc, argv);
    if (flag_option(args, "help")) {
        std::printf("%s\n", options.help().c_str());
        return 0;
    }
    const bool stages = flag_option(args, "stages");
    if (flag_option(args, "json")) {
        SceneJson j = SceneJson::array();
        if (stages)
            for (const StageInfo& s : kStepStages)
                j.push_back({{"stage", s.name}, {"module", s.module}, {"runs", s.runs}, {"does", s.does}});
        else
            for (const ParamDoc& d : scene_schema())
                j.push_back({{"key", d.path}, {"type", d.type}, {"default", d.default_text}, {"allowed", d.allowed},
                             {"unit", d.unit}, {"meaning", d.doc}});
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    if (flag_option(args, "markdown")) {
        if (stages)
            print_stages_markdown();
        else
            print_keys_markdown();
        return 0;
    }
    if (stages) {
        for (const StageInfo& s : kStepStages) std::printf("%-18s %-34s %s\n", s.name, s.module, s.does);
        return 0;
    }
    for (const ParamDoc& d : scene_schema())
        std::printf("%-36s %-16s default %-22s %s%s%s\n", d.path.c_str(), d.type.c_str(), d.default_text.c_str(),
                    d.allowed.empty() ? "" : (d.allowed + "; ").c_str(), d.unit.empty() ? "" : (d.unit + "; ").c_str(),
                    d.doc.c_str());
    return 0;
}

}  // namespace mw
