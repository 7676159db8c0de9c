// Pieces shared by the `meltwater` subcommands: option parsing that turns cxxopts' exceptions into
// one-line InputErrors, scene loading from the command line, backend choice, number formatting.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <cxxopts.hpp>

#include "simulation/simulation.hpp"
#include "apps/scene.hpp"

namespace mw {

// Adds the positional SCENE argument and --set to `options`.
void add_scene_options(cxxopts::Options& options);

// Parses, converting every cxxopts complaint (unknown option, missing or bad value) to InputError.
// An option followed by another option instead of its value (`--steps --quiet`) is refused.
// `--set K=V` / `--set=K=V` are taken out first and kept in order in `overrides` (cxxopts would
// split their values at commas, breaking `--set gravity=[0,-1,0]`).
cxxopts::ParseResult parse_options(cxxopts::Options& options, int argc, char** argv,
                                   std::vector<std::string>* overrides = nullptr);

// Whether the flag `name` is set: `--quiet` and `--quiet=true` set it, `--quiet=false` does not.
bool flag_option(const cxxopts::ParseResult& args, const std::string& name);

// The scene named on the command line (or the built-in default) with the --set overrides applied.
Scene scene_from_options(const cxxopts::ParseResult& result, const std::vector<std::string>& overrides);

// "auto" (CUDA when a GPU is usable, else OpenMP), "cuda" or "openmp". Throws InputError for an
// unknown name and DeviceError when CUDA is asked for and unavailable.
std::string choose_backend(const std::string& requested);

// A simulation of `setup` built on the host backend with the memory layout `backend` ("cuda" or
// "openmp") would use: neighbour lists or grid gathers, the only part of the layout that differs.
// Its device_bytes() is what the scene needs on that backend; it allocates all of it on the host.
std::unique_ptr<Simulation> probe_on_host(SimulationSetup setup, const std::string& backend);

// Creates the simulation on the chosen backend; a DeviceError on creation (out of GPU memory) is
// re-thrown with the particle count and the memory estimate.
std::unique_ptr<Simulation> create_simulation(const SimulationSetup& setup, const std::string& backend, int threads);

// Refuses (DeviceError, before anything is allocated) a scene whose host memory would exceed what
// the machine has available (MemAvailable; no check where that cannot be read). `host_layout`:
// the simulation runs on the host (openmp, or `info` measuring a layout there) rather than on a
// GPU, where the host keeps only the initial particles and frame buffers.
void check_host_memory(const Scene& scene, const std::string& backend, bool host_layout);
// The estimate check_host_memory compares with the available memory, in bytes.
double host_bytes_needed(const Scene& scene, const std::string& backend, bool host_layout);

// Numeric options are declared as strings (cxxopts::value<std::string>()) and converted here, so
// that a bad value is reported by its option's name in this program's words; cxxopts' own
// conversion errors name only the value. Each returns `fallback` when the option is absent and
// throws InputError for text that is not entirely a number (or is out of range, or not finite).
long integer_option(const cxxopts::ParseResult& args, const std::string& name, long fallback);
double number_option(const cxxopts::ParseResult& args, const std::string& name, double fallback);

// The --threads option: 0 when absent, else a count in [1, 1024] (InputError otherwise). Each
// OpenMP thread reserves a stack, and libgomp crashes when it cannot create tens of thousands.
int threads_option(const cxxopts::ParseResult& args);

std::string with_thousands(long n);
std::string count_of(long n, const std::string& noun);  // "1 step", "1,209 steps"
std::string format_number(double v);  // %g: 1e+300, 0.02
std::string format_bytes(double bytes);
std::string format_duration(double seconds);  // h:mm:ss or m:ss

}  // namespace mw
