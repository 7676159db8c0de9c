// `meltwater backends`: what this build has, and the device each backend would use.
#include <cstdio>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "simulation/factory.hpp"

namespace mw {

int command_backends(int argc, char** argv) {
    cxxopts::Options options("meltwater backends", "The backends compiled into this program and the devices found.");
    options.add_options()("json", "print one JSON object instead of text")("h,help", "show this help");
    const cxxopts::ParseResult args = parse_options(options, argc, argv);
    if (flag_option(args, "help")) {
        std::printf("%s\n", options.help().c_str());
        return 0;
    }
    const BackendInfo infos[] = {cuda_backend_info(), openmp_backend_info()};
    const std::string chosen = choose_backend("auto");
    if (flag_option(args, "json")) {
        SceneJson j;
        for (const BackendInfo& b : infos)
            j["backends"].push_back({{"name", b.name}, {"compiled", b.compiled}, {"available", b.available},
                                     {"description", b.description}});
        j["auto"] = chosen;
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    for (const BackendInfo& b : infos)
        std::printf("%-7s %-24s %s\n", b.name.c_str(),
                    !b.compiled ? "not compiled" : b.available ? "compiled, available" : "compiled, unavailable",
                    b.description.c_str());
    std::printf("--backend auto picks %s\n", chosen.c_str());
    return 0;
}

}  // namespace mw
