#include "apps/cli_common.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <set>

#include "apps/scene_builder.hpp"
#include "simulation/factory.hpp"
#include "common/errors.hpp"

namespace mw {

namespace {
// cxxopts names the offending token between its quotes (typographic or ASCII, by platform); the
// token alone lets the message be worded in this program's style.
std::string quoted_token(const std::string& message) {
    for (const char* open : {"\u2018", "'"}) {
        const char* close = open[0] == '\'' ? "'" : "\u2019";
        const std::size_t begin = message.find(open);
        if (begin == std::string::npos) continue;
        const std::size_t first = begin + std::string(open).size();
        const std::size_t end = message.find(close, first);
        if (end != std::string::npos) return message.substr(first, end - first);
    }
    return message;
}

// Whether a word reads as an option rather than a value: "--quiet", "-q". Numbers ("-5",
// "-inf") and lists of them ("-1,0,0" for --translate) are values.
bool looks_like_option(const std::string& word) {
    if (word.size() < 2 || word[0] != '-') return false;
    if (word[1] == '-') return true;
    double number = 0;
    const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), number);
    const bool starts_with_number = error == std::errc() || error == std::errc::result_out_of_range;
    return !starts_with_number && std::isalpha(static_cast<unsigned char>(word[1]));
}

// The spellings ("--steps", "-s") of the options that take their value as the next word: all but
// the flags, which have an implicit value.
std::set<std::string> options_taking_a_value(const cxxopts::Options& options) {
    std::set<std::string> names;
    for (const std::string& group : options.groups())
        for (const cxxopts::HelpOptionDetails& option : options.group_help(group).options) {
            if (option.has_implicit) continue;
            if (!option.s.empty()) names.insert("-" + option.s);
            for (const std::string& name : option.l) names.insert("--" + name);
        }
    return names;
}
}  // namespace

void add_scene_options(cxxopts::Options& options) {
    options.add_options()
        ("scene", "scene file (JSON); the built-in 3D dam break when omitted", cxxopts::value<std::string>())
        ("set", "override a scene key, e.g. --set solver.dt=0.002 or --set gravity=[0,-1,0] (repeatable)",
         cxxopts::value<std::string>(), "K=V")
        ("h,help", "show this help");
    options.parse_positional({"scene"});
    options.positional_help("[SCENE]");
}

cxxopts::ParseResult parse_options(cxxopts::Options& options, int argc, char** argv,
                                   std::vector<std::string>* overrides) {
    std::vector<char*> rest;
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        if (overrides && i > 0 && a == "--set") {
            if (i + 1 >= argc) throw InputError("--set needs KEY=VALUE, for example --set solver.dt=0.002");
            overrides->push_back(argv[++i]);
        } else if (overrides && i > 0 && a.rfind("--set=", 0) == 0) {
            overrides->push_back(a.substr(6));
        } else {
            rest.push_back(argv[i]);
        }
    }
    // cxxopts gives an option that takes a value the next word whatever it is: `--steps --quiet`
    // would make "--quiet" the step count, `--out -q` a directory named "-q". A value written with
    // '=' (`--out=-q`) or after "--" is taken as written.
    const std::set<std::string> takes_value = options_taking_a_value(options);
    for (std::size_t i = 1; i + 1 < rest.size(); ++i) {
        const std::string word = rest[i], next = rest[i + 1];
        if (word == "--") break;
        if (takes_value.count(word) && looks_like_option(next))
            throw InputError(word + " needs a value, but is followed by the option '" + next + "'");
        if (takes_value.count(word)) ++i;  // its value, whatever it looks like, is not an option
    }
    try {
        cxxopts::ParseResult result = options.parse(static_cast<int>(rest.size()), rest.data());
        if (!result.unmatched().empty()) {
            const std::string hint = overrides ? " (one scene at most)" : "";
            throw InputError("unexpected argument '" + result.unmatched().front() + "'" + hint);
        }
        // cxxopts keeps the last of a repeated option; a repeated --out or --steps is more likely
        // a mistake than an intent, so say so (--set, the one repeatable option, is taken above).
        const auto& given = result.arguments();
        for (std::size_t a = 0; a < given.size(); ++a)
            for (std::size_t b = 0; b < a; ++b)
                if (given[a].key() == given[b].key())
                    throw InputError("--" + given[a].key() + " is given more than once ('" + given[b].value() +
                                     "', then '" + given[a].value() + "'); give it once");
        return result;
    } catch (const cxxopts::exceptions::incorrect_argument_type& e) {
        // Only flags are typed for cxxopts (every other value is a string, converted by
        // integer_option and number_option), and a flag takes a value only as `--flag=value`.
        const std::string value = quoted_token(e.what());
        std::string flag = "a flag";
        for (const char* a : rest) {
            const std::string given = a;
            const std::size_t eq = given.find('=');
            if (given.rfind("--", 0) == 0 && eq != std::string::npos && given.substr(eq + 1) == value)
                flag = given.substr(0, eq);
        }
        throw InputError(flag + ": '" + value + "' is not true or false");
    } catch (const cxxopts::exceptions::missing_argument& e) {
        throw InputError("--" + quoted_token(e.what()) + " needs a value");
    } catch (const cxxopts::exceptions::no_such_option& e) {
        const std::string name = quoted_token(e.what());
        throw InputError("unknown option '" + std::string(name.size() == 1 ? "-" : "--") + name + "'");
    } catch (const cxxopts::exceptions::exception& e) {
        throw InputError(e.what());
    }
}

bool flag_option(const cxxopts::ParseResult& args, const std::string& name) {
    // A flag is a bool with an implicit "true": `--quiet=false` parses to false, and count() alone
    // would take it as set.
    return args.count(name) > 0 && args[name].as<bool>();
}

Scene scene_from_options(const cxxopts::ParseResult& result, const std::vector<std::string>& overrides) {
    std::string path;
    if (result.count("scene")) {
        path = result["scene"].as<std::string>();
        if (path.empty()) throw InputError("empty scene path");
    }
    return load_scene(path, overrides);
}

std::string choose_backend(const std::string& requested) {
    if (requested == "openmp") return "openmp";
    if (requested == "cuda") {
        const BackendInfo cuda = cuda_backend_info();
        if (!cuda.available) throw DeviceError("--backend cuda: CUDA is not available: " + cuda.description);
        return "cuda";
    }
    if (requested == "auto") return cuda_backend_info().available ? "cuda" : "openmp";
    throw InputError("--backend: expected auto, cuda or openmp, got '" + requested + "'");
}

std::unique_ptr<Simulation> probe_on_host(SimulationSetup setup, const std::string& backend) {
    const BackendInfo target = backend == "cuda" ? cuda_backend_info() : openmp_backend_info();
    NeighborParams::Lists& lists = setup.params.neighbors.lists;
    if (lists == NeighborParams::Lists::kAuto)
        lists = target.prefers_neighbor_lists ? NeighborParams::Lists::kOn : NeighborParams::Lists::kOff;
    return create_openmp_simulation(setup, 0);
}

std::unique_ptr<Simulation> create_simulation(const SimulationSetup& setup, const std::string& backend, int threads) {
    if (backend == "openmp") return create_openmp_simulation(setup, threads);
    try {
        return create_cuda_simulation(setup);
    } catch (const DeviceError& e) {
        // Add what the scene needs on the GPU, measured on the host, when that is cheap enough
        // (a few hundred MB of host memory at most); otherwise point to `info`.
        std::string estimate = "; 'meltwater info --backend cuda' gives the memory it needs";
        if (setup.position.size() <= 5'000'000) {
            try {
                estimate = ", which need " + format_bytes(double(probe_on_host(setup, "cuda")->device_bytes())) + " on the GPU";
            } catch (const std::exception&) {
            }
        }
        throw DeviceError(std::string(e.what()) + " (scene: " + with_thousands(long(setup.position.size())) +
                          " particles" + estimate + ")");
    }
}

namespace {
// Bytes of host memory the machine can still give, from /proc/meminfo; 0 when unknown.
double available_host_bytes() {
    std::FILE* f = std::fopen("/proc/meminfo", "r");
    if (!f) return 0;
    char line[256];
    double kib = 0;
    while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "MemAvailable: %lf kB", &kib) == 1) break;
    std::fclose(f);
    return kib * 1024;
}
}  // namespace

double host_bytes_needed(const Scene& scene, const std::string& backend, bool host_layout) {
    // Peak host memory per particle, measured with /usr/bin/time on the 1M dam break (992k fluid,
    // 568k wall particles, h = 2 r0; the development VM): 459 MB building the
    // OpenMP layout (neighbour lists), 277 MB the CUDA layout (grid gathers), which these figures
    // reproduce within 2%. A GPU run keeps only the initial particles and frame buffers on the
    // host (about 100 bytes per particle). The lists' share (about 180 of the 420 bytes at
    // h = 2 r0) grows with the neighbour count, (h / 2 r0)³: at 2.5 r0 the benchmark's lists case
    // holds 691 bytes per fluid particle against 443 at 2 r0 (bench/results/...-session14-kernels.md).
    const ParticleEstimate n = estimate_particles(scene);
    const bool lists = scene.params.neighbors.lists == NeighborParams::Lists::kAuto
                           ? backend == "openmp"
                           : scene.params.neighbors.lists == NeighborParams::Lists::kOn;
    const double width = double(scene.params.fluid.support_radius) / (2.0 * double(scene.params.fluid.spacing));
    const double list_bytes = 180.0 * width * width * width;
    const double fluid_bytes = !host_layout ? 100.0 : lists ? 240.0 + list_bytes : 240.0;
    const double boundary_bytes = host_layout ? 60.0 : 100.0;
    return n.fluid * fluid_bytes + n.boundary * boundary_bytes;
}

void check_host_memory(const Scene& scene, const std::string& backend, bool host_layout) {
    const double available = available_host_bytes();
    if (available <= 0) return;
    const ParticleEstimate n = estimate_particles(scene);
    const double needed = host_bytes_needed(scene, backend, host_layout);
    if (needed > available)
        throw DeviceError("the scene needs about " + format_bytes(needed) + " of host memory (" +
                          with_thousands(long(n.total())) + " particles before objects), but only " +
                          format_bytes(available) + " is available; increase fluid.spacing or shrink the scene");
}

namespace {
// All of `text` as a T (std::from_chars: no leading '+', no whitespace and no locale, so "2.5"
// means 2.5 everywhere), or an InputError naming the option and the `expected` kind of value.
template <class T>
T option_value(const std::string& name, const std::string& text, const char* expected) {
    T value{};
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error == std::errc::result_out_of_range) throw InputError("--" + name + ": '" + text + "' is out of range");
    if (error != std::errc() || end != text.data() + text.size() || text.empty())
        throw InputError("--" + name + ": expected " + expected + ", got '" + text + "'");
    return value;
}
}  // namespace

long integer_option(const cxxopts::ParseResult& args, const std::string& name, long fallback) {
    if (!args.count(name)) return fallback;
    return option_value<long>(name, args[name].as<std::string>(), "a whole number");
}

double number_option(const cxxopts::ParseResult& args, const std::string& name, double fallback) {
    if (!args.count(name)) return fallback;
    const std::string text = args[name].as<std::string>();
    const double value = option_value<double>(name, text, "a number");
    if (!std::isfinite(value)) throw InputError("--" + name + ": expected a finite number, got '" + text + "'");
    return value;
}

int threads_option(const cxxopts::ParseResult& args) {
    if (!args.count("threads")) return 0;
    constexpr long kMaxThreads = 1024;
    const long threads = integer_option(args, "threads", 0);
    if (threads < 1 || threads > kMaxThreads)
        throw InputError("--threads must be in [1, " + std::to_string(kMaxThreads) + "], got " + std::to_string(threads));
    return static_cast<int>(threads);
}

std::string format_number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

std::string with_thousands(long n) {
    std::string digits = std::to_string(n < 0 ? -n : n), out;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i && (digits.size() - i) % 3 == 0) out += ',';
        out += digits[i];
    }
    return n < 0 ? "-" + out : out;
}

std::string count_of(long n, const std::string& noun) { return with_thousands(n) + " " + noun + (n == 1 ? "" : "s"); }

std::string format_bytes(double bytes) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
    int u = 0;
    while (bytes >= 1024 && u < 4) bytes /= 1024, ++u;
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, u ? "%.1f %s" : "%.0f %s", bytes, units[u]);
    return buffer;
}

std::string format_duration(double seconds) {
    if (!std::isfinite(seconds) || seconds < 0) return "--:--";
    long s = std::lround(seconds);
    char buffer[32];
    if (s >= 3600) std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
    else std::snprintf(buffer, sizeof buffer, "%ld:%02ld", s / 60, s % 60);
    return buffer;
}

}  // namespace mw
