// `meltwater`: the command line. Dispatches to one subcommand; every error a user can cause is
// one line on stderr and a non-zero exit.
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include "apps/commands.hpp"
#include "common/errors.hpp"

namespace {
void print_usage(std::FILE* to) {
    std::fprintf(to,
        "usage: meltwater <command> [options]\n"
        "  run [SCENE]      simulate a scene (the built-in 3D dam break when no scene is given)\n"
        "  info [SCENE]     particle counts, memory estimate and the stages that will run\n"
        "  backends         the backends compiled in and the devices found\n"
        "  sample MESH      sample a mesh into surface, inner and geometry particles\n"
        "  schema           every scene key with its default and meaning; --stages: the time step\n"
        "  plot RUN_DIR     draw a run's stats.csv (step size, errors, speeds, stage times) as a PNG\n"
        "  render RUN_DIR   draw a run's frames as pictures (frames/preview_NNNNN.png)\n"
        "Run 'meltwater <command> --help' for the options of a command; 'meltwater --version' for the version.\n");
}
}  // namespace

int main(int argc, char** argv) {
    if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
        print_usage(argc < 2 ? stderr : stdout);  // no command is an error: usage on stderr, exit 2
        return argc < 2 ? 2 : 0;
    }
    if (!std::strcmp(argv[1], "--version") || !std::strcmp(argv[1], "-V")) {
        std::printf("meltwater %s\n", MW_VERSION);
        return 0;
    }
    const std::string command = argv[1];
    try {
        if (command == "run") return mw::command_run(argc - 1, argv + 1);
        if (command == "info") return mw::command_info(argc - 1, argv + 1);
        if (command == "backends") return mw::command_backends(argc - 1, argv + 1);
        if (command == "sample") return mw::command_sample(argc - 1, argv + 1);
        if (command == "schema") return mw::command_schema(argc - 1, argv + 1);
        if (command == "plot") return mw::command_plot(argc - 1, argv + 1);
        if (command == "render") return mw::command_render(argc - 1, argv + 1);
        std::fprintf(stderr, "meltwater: error: unknown command '%s' (run, info, backends, sample, schema, plot, render)\n",
                     mw::printable(command.c_str()).c_str());
        return 2;
    } catch (const mw::InputError& e) {
        std::fprintf(stderr, "meltwater: error: %s\n", mw::printable(e.what()).c_str());
        return 2;
    } catch (const mw::DeviceError& e) {
        std::fprintf(stderr, "meltwater: device error: %s\n", mw::printable(e.what()).c_str());
        return 3;
    } catch (const mw::SimulationError& e) {
        std::fprintf(stderr, "meltwater: simulation failed: %s\n", mw::printable(e.what()).c_str());
        return 4;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr,
                     "meltwater: error: out of host memory (a coarser spacing or a smaller scene or mesh needs "
                     "less; 'meltwater info SCENE' estimates what a scene needs)\n");
        return 3;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "meltwater: error: %s\n", mw::printable(e.what()).c_str());
        return 1;
    }
}
