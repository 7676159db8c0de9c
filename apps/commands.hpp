// The subcommands of `meltwater`. Each takes the arguments after its name (argv[0] is
// "meltwater <command>") and returns the process exit code; bad input throws InputError.
#pragma once

namespace mw {
int command_run(int argc, char** argv);
int command_info(int argc, char** argv);
int command_backends(int argc, char** argv);
int command_sample(int argc, char** argv);
int command_schema(int argc, char** argv);
int command_plot(int argc, char** argv);
int command_render(int argc, char** argv);
}  // namespace mw
