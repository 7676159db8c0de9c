// Fluid benchmark: ms per step by stage, particle-steps per second, PCISPH iterations, density
// error and bytes per particle, side by side in one run.
//   1. Dam breaks of about 25k, 100k and 1M fluid particles (4M with --large, for a GPU).
//   2. The SPlisHSPlasH comparison (scenes/splishsplash_block.json): a 1 m fluid block at 0.05 m
//      and at 0.025 m spacing in a 4 x 3 x 1.5 m box, dt 0.001 s, eta 1%, >= 3 iterations, with
//      the scenes' default peak bound (eta_max 5%) and with the peak bounded at 1%.
//   3. The same dam break with linear and Z-order cell orderings, with grid gathers, and with
//      viscosity (Eq. 4 with the fluid's mirror images across the walls; the backend's gathers).
//   4. The Wendland C2 kernel at h = 2 r0 and 2.5 r0 (fluid.kernel).
//   5. The time step's trade: the default scene (scenes/dam_break.json) run whole at its CFL
//      number 0.4 under 1.5 ms and at CFL 0.4, 0.6, 0.8 and 1 under the paper's 30 ms: steps,
//      iterations, time to the end, and how far its kinetic energy strays from the first run's.
//   6. Static mesh objects: scenes/dam_break_cylinder.json (the default scene with a static
//      cylinder in the surge's path) run to t = 1 s with the object's velocity–position correction
//      and without it (the walls' on in both), at CFL 0.4 under 1.5 ms and at CFL 1 under 30 ms:
//      steps, time, and how much fluid got inside the cylinder.
//   7. Coupling with moving solids: scenes/floating_boxes.json (two rigid boxes and an elastic
//      cube settling in a pool) run two-way, with and without the velocity–position correction
//      against them, and without coupling.strong: steps, ms per step, the coupling stages'
//      share, top speed.
//   7b. The extremes: scenes/thrown_cube.json (a 0.12 m cube thrown down at 5 m/s into a pool)
//      rigid (with and without coupling.strong) and elastic, at 100, 500, 2,000 and 10,000 kg/m³,
//      at CFL 0.4 and at CFL 1 under 30 ms: whether it runs to the end, steps, time, and how the
//      cube ends; and a flat box (0.24 x 0.08 x 0.24 m) of 2,000 to 10,000 kg/m³ let go from rest
//      under water onto the film over the floor, the same way.
//   7c. The largest steps: the same throws at CFL 0.4, 0.7 and 1 (steps up to 30 ms) and at fixed
//      steps of 1 to 30 ms, each judged as tests/core/test_extremes.cpp judges its cases: up to
//      which setting a case holds, and how the next one fails.
//   8. Heat conduction: scenes/warm_jelly.json (a warm elastic cube and a warm rigid block in cold
//      water) without heat, and with it at its diffusivities and at 5 and 25 times them: steps,
//      ms per step, the heat stage's median and its sub-steps.
//   9. Melting: scenes/melting_ice.json (an ice cube in warm water) with ice's latent heat and
//      without: particles melted, ms per step, and the melting stage's cost on the steps where
//      something melted (the exposure and the regions' rebuild) and on the others.
//  10. The paper's Table 2, the rows the product can run: Fig. 8, a stream poured onto a pinned
//      elastic bunny (scenes/bunny_stream.json), once the stream has brought 20,000 fluid particles
//      (the paper's 25k); Fig. 9, a stream poured into a thin elastic box
//      (scenes/thin_box_pour.json), and Fig. 10, a stream poured onto a cloth
//      (scenes/cloth_stream.json), each once it has brought 10,000 (the paper's 15k); and Fig. 1 at
//      CI size, a stream down a stair over four hollow objects (scenes/stair_flow.json), once it
//      has brought 8,000; Fig. 11b at CI size, four melting cubes under streams
//      (scenes/melting_streams.json), once they have brought 3,600: the particle counts and the
//      stages' medians, beside the paper's rows.
// Prints a Markdown report and, with --out FILE, appends it there, each section as soon as it is
// measured.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli_common.hpp"
#include "apps/scene.hpp"
#include "apps/scene_builder.hpp"
#include "apps/speed_limit.hpp"
#include "algorithms/pcisph_delta.hpp"
#include "algorithms/sph_kernels.hpp"
#include "simulation/factory.hpp"
#include "sampling/box_particles.hpp"
#include "sampling/wall_gap.hpp"
#include "surface/fluid_surface.hpp"

using namespace mw;

namespace {

struct Options {
    std::string backend = "openmp";
    int threads = 0;
    bool large = false;
    bool quick = false;
    std::string out;
    // The report's sections to run (--sections, comma-separated): all by default.
    std::vector<std::string> sections{"dams", "splish", "variants", "kernels", "steps", "objects", "coupling", "extremes", "largest_steps", "heat", "melting", "paper"};
    bool wants(const std::string& section) const {
        return std::find(sections.begin(), sections.end(), section) != sections.end();
    }
};

struct Result {
    std::string name;
    long fluid = 0, total = 0;
    int steps = 0;
    double start_time = 0;  // simulated time at the first measured step
    std::vector<std::string> stages;
    std::vector<double> stage_median_ms;
    double total_median_ms = 0;
    double iterations_avg = 0;
    double error_avg = 0, error_max = 0;
    double bytes_per_fluid = 0, bytes_per_particle = 0;
};

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

std::unique_ptr<Simulation> make(const Options& o, const SimulationSetup& setup) {
    return o.backend == "cuda" ? create_cuda_simulation(setup) : create_openmp_simulation(setup, o.threads);
}

// Runs `warmup` steps, and on until simulated time `warmup_time`, untimed; then measures `steps`.
Result measure(const Options& o, const std::string& name, const SimulationSetup& setup, int steps, int warmup,
               double warmup_time = 0) {
    auto sim = make(o, setup);
    Result r;
    r.name = name;
    r.fluid = sim->counts().by_type[kFluid];
    r.total = sim->counts().total();
    r.steps = steps;
    r.stages = sim->stage_names();
    std::vector<std::vector<double>> stage_ms(r.stages.size());
    std::vector<double> total_ms;
    double iterations = 0;
    for (int s = 0; s < warmup || sim->time() < warmup_time; ++s) sim->step();
    r.start_time = sim->time();
    for (int s = 0; s < steps; ++s) {
        sim->step();
        const StepReport& rep = sim->last_report();
        for (std::size_t k = 0; k < r.stages.size(); ++k) stage_ms[k].push_back(rep.stage_ms[k]);
        total_ms.push_back(rep.total_ms);
        iterations += rep.iterations;
        r.error_avg += rep.density_error_avg;
        r.error_max = std::max(r.error_max, rep.density_error_max);
    }
    // Memory after the run: every per-step buffer (sort keys, neighbour lists) has grown by now.
    r.bytes_per_fluid = double(sim->device_bytes()) / double(std::max(1L, r.fluid));
    r.bytes_per_particle = double(sim->device_bytes()) / double(std::max(1L, r.total));
    for (auto& v : stage_ms) r.stage_median_ms.push_back(median(v));
    r.total_median_ms = median(total_ms);
    r.iterations_avg = iterations / steps;
    r.error_avg /= steps;
    std::string stages;
    char cell[64];
    for (std::size_t k = 0; k < r.stages.size(); ++k) {
        std::snprintf(cell, sizeof cell, "%s%s %.2f", k ? " " : "", r.stages[k].c_str(), r.stage_median_ms[k]);
        stages += cell;
    }
    std::fprintf(stderr, "  %-34s %9ld fluid %8.2f ms/step (%s; %.1f iterations, %.0f bytes/fluid particle)\n",
                 name.c_str(), r.fluid, r.total_median_ms, stages.c_str(), r.iterations_avg, r.bytes_per_fluid);
    return r;
}

// A dam break of about `target` fluid particles: a 0.6 x 0.8 x 0.8 m column in a 1.6 x 1.0 x
// 0.8 m tank (the default scene's shape), spacing chosen for the count, dt scaled with spacing;
// the kernel `kernel` with support `support_in_r0` r0.
SimulationSetup dam_break(long target, CellOrdering ordering, KernelKind kernel = KernelKind::kCubicSpline,
                          Real support_in_r0 = 2) {
    const double volume = 0.6 * 0.8 * 0.8;
    const Real r0 = Real(std::cbrt(volume / double(target)));
    SimulationSetup s;
    s.params.domain_min = {0, 0, 0};
    s.params.domain_max = {1.6f, 1.0f, 0.8f};
    s.params.fluid.spacing = r0;
    s.params.fluid.support_radius = support_in_r0 * r0;
    s.params.fluid.kernel = kernel;
    s.params.solver.dt = Real(0.0015 * r0 / 0.02);
    s.params.solver.eta_max = Real(default_eta_max(s.params.solver.eta));  // the scenes' stopping rule
    s.params.neighbors.ordering = ordering;
    for (const Vec3& p : fill_box_lattice({0, 0, 0}, {0.6f, 0.8f, 0.8f}, r0)) {
        s.position.push_back(p);
        s.type.push_back(kFluid);
    }
    s.params.boundary.walls = true;
    const Real gap = rest_density_wall_gap(r0, s.params.fluid.support_radius, r0 / 2, 1, kernel);
    s.params.boundary.wall_gap = gap;
    s.params.boundary.correction = true;  // as scenes/dam_break.json runs
    for (const Vec3& p : sample_container_walls(s.params.domain_min, s.params.domain_max, r0 / 2, 1, gap)) {
        s.position.push_back(p);
        s.type.push_back(kStaticBoundary);
    }
    s.velocity.assign(s.position.size(), Vec3{0, 0, 0});
    s.object.assign(s.position.size(), -1);
    return s;
}

SimulationSetup with_lists(SimulationSetup s, bool lists) {
    s.params.neighbors.lists = lists ? NeighborParams::Lists::kOn : NeighborParams::Lists::kOff;
    return s;
}

// A whole run to `end_time`: what the time step's choice costs and what it changes.
struct WholeRun {
    std::string name;
    long fluid = 0;
    long steps = 0, iterations = 0, halvings = 0, unconverged = 0, diverged = 0;
    double ms_total = 0;  // the stages' time summed over every step
    double error_max = 0, top_speed = 0;
    std::vector<double> time, kinetic_energy;  // after each step
    long most_inside = 0;                      // objects section: most fluid inside the object after a step
    double closest = 1e30;                     // ... and the closest any came to its surface, m (< 0: inside)
    double energy_at(double t) const {  // linear between the steps around t
        std::size_t k = 1;
        while (k + 1 < time.size() && time[k] < t) ++k;
        const double w = (t - time[k - 1]) / (time[k] - time[k - 1]);
        return kinetic_energy[k - 1] + w * (kinetic_energy[k] - kinetic_energy[k - 1]);
    }
};

// A CFL number and a largest step, applied to a shipped scene as overrides: the whole-run
// sections' cases.
struct StepCase {
    const char* cfl_number;
    const char* largest;
    std::string name() const { return std::string("CFL ") + cfl_number + ", largest step " + largest + " s"; }
};
Scene scene_at_step(const char* scene_file, StepCase c) {
    return load_scene(std::string(MW_SOURCE_DIR) + "/scenes/" + scene_file,
                      {std::string("solver.cfl_number=") + c.cfl_number, std::string("solver.dt=") + c.largest});
}

// Called after every step of a whole run (to look at the particles).
using StepObserver = std::function<void(Simulation&, WholeRun&)>;

WholeRun run_whole(const Options& o, const std::string& name, const SimulationSetup& setup, double end_time,
                   const StepObserver& observe = nullptr) {
    auto sim = make(o, setup);
    WholeRun r;
    r.name = name;
    r.fluid = sim->counts().by_type[kFluid];
    r.time.push_back(0);
    r.kinetic_energy.push_back(0);  // the column starts at rest
    while (sim->time() < end_time) {
        sim->step();
        const StepReport& rep = sim->last_report();
        ++r.steps;
        r.iterations += rep.iterations;
        r.halvings += rep.retries;
        r.unconverged += rep.unconverged;
        r.diverged += rep.diverged;
        r.ms_total += rep.total_ms;
        r.error_max = std::max(r.error_max, rep.density_error_max);
        r.top_speed = std::max(r.top_speed, rep.max_speed);
        r.time.push_back(sim->time());
        r.kinetic_energy.push_back(rep.kinetic_energy);
        if (observe) observe(*sim, r);
    }
    std::fprintf(stderr, "  %-44s %6ld steps %7ld iterations %8.2f s\n", name.c_str(), r.steps, r.iterations,
                 r.ms_total / 1000);
    return r;
}

// The first run is the reference: the others' kinetic energy is compared with its at every
// tenth of a second.
std::string format_whole_runs(const std::vector<WholeRun>& runs, double end_time) {
    std::ostringstream t;
    t << "| case | steps | halvings of a step | unconverged | diverged | iterations | iterations/step | s to the end | "
         "ms/step | peak density error | top speed m/s | kinetic energy, largest deviation from the first row |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    char cell[320];
    for (const WholeRun& r : runs) {
        double deviation = 0;
        for (int k = 1; k <= int(std::floor(end_time * 10 + 1e-9)); ++k) {
            const double reference = runs.front().energy_at(0.1 * k);
            if (reference > 0) deviation = std::max(deviation, std::fabs(r.energy_at(0.1 * k) - reference) / reference);
        }
        std::snprintf(cell, sizeof cell, "| %s | %ld | %ld | %ld | %ld | %ld | %.2f | %.2f | %.2f | %.2f%% | %.2f | %.1f%% |\n",
                      r.name.c_str(), r.steps, r.halvings, r.unconverged, r.diverged, r.iterations,
                      double(r.iterations) / double(r.steps), r.ms_total / 1000, r.ms_total / double(r.steps),
                      100 * r.error_max, r.top_speed, 100 * deviation);
        t << cell;
    }
    return t.str();
}

// The median of a per-step column, "–" when there is none.
std::string median_text(std::vector<double> v) {
    if (v.empty()) return "–";
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    char text[32];
    std::snprintf(text, sizeof text, "%.2f", v[v.size() / 2]);
    return text;
}

std::string format_table(const std::vector<Result>& results) {
    std::ostringstream t;
    std::vector<std::string> stages;
    for (const Result& r : results)
        for (const std::string& s : r.stages)
            if (std::find(stages.begin(), stages.end(), s) == stages.end()) stages.push_back(s);
    t << "| case | fluid | all particles | from t (s) | steps |";
    for (const auto& s : stages) t << " ms " << s << " |";
    t << " ms total | fluid particle-steps/s | iterations | density error avg | max | bytes/fluid particle | bytes/particle |\n|---|---|---|---|---|";
    for (std::size_t i = 0; i < stages.size(); ++i) t << "---|";
    t << "---|---|---|---|---|---|---|\n";
    char cell[128];
    for (const Result& r : results) {
        std::snprintf(cell, sizeof cell, " %.3f |", r.start_time);
        t << "| " << r.name << " | " << r.fluid << " | " << r.total << " |" << cell << " " << r.steps << " |";
        for (const auto& s : stages) {
            auto it = std::find(r.stages.begin(), r.stages.end(), s);
            if (it == r.stages.end()) {
                t << " – |";
            } else {
                std::snprintf(cell, sizeof cell, " %.2f |", r.stage_median_ms[it - r.stages.begin()]);
                t << cell;
            }
        }
        std::snprintf(cell, sizeof cell, " %.2f | %.3g | %.1f | %.3f%% | %.2f%% | %.0f | %.0f |\n", r.total_median_ms,
                      r.fluid / (r.total_median_ms / 1000.0), r.iterations_avg, 100 * r.error_avg, 100 * r.error_max,
                      r.bytes_per_fluid, r.bytes_per_particle);
        t << cell;
    }
    return t.str();
}

// One row of the paper's Table 2 (docs/method.md) for a shipped scene with a stream: the particle
// counts and the stages' medians over the steps once `from_fluid` fluid particles are in, and one
// mesh of the fluid's surface at each of the scene's frame times (it changes no step), beside the
// paper's row.
std::string table2_row(const Options& o, const std::string& label, const std::string& scene_file, double end_time,
                       long from_fluid, const std::string& paper_row, const std::string& note) {
    const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/" + scene_file);
    const SimulationSetup setup = build_setup(scene);
    std::vector<std::string> names;
    std::vector<std::vector<double>> stage_ms;
    std::vector<double> step_ms, surface_ms, field_ms;
    long fluid = 0, measured = 0, triangles = 0;
    double next_surface = 0;
    HostParticles host;
    FluidSurfacer surfacer(scene.params, scene.surface_voxel, o.threads);
    const StepObserver stage_times = [&](Simulation& sim, WholeRun&) {
        fluid = sim.counts().by_type[kFluid];
        if (fluid < from_fluid) return;
        if (names.empty()) names = sim.stage_names(), stage_ms.resize(names.size());
        const StepReport& rep = sim.last_report();
        for (std::size_t k = 0; k < names.size() && k < rep.stage_ms.size(); ++k) stage_ms[k].push_back(rep.stage_ms[k]);
        step_ms.push_back(rep.total_ms);
        ++measured;
        if (sim.time() + 1e-9 < next_surface) return;
        next_surface = sim.time() + 1.0 / scene.fps;
        sim.download(host);  // a frame's download, which the run makes for its frames anyway
        const FluidSurfacer::Surface surface = surfacer.build(sim, host);
        triangles = long(surface.mesh.triangles.size());
        surface_ms.push_back(surface.ms);
        field_ms.push_back(surface.field_ms);
    };
    const WholeRun r = run_whole(o, label, setup, end_time, stage_times);
    const ParticleCounts counts = count_particles(setup);
    auto stage = [&](const std::string& name) {
        for (std::size_t k = 0; k < names.size(); ++k)
            if (names[k] == name) return median_text(stage_ms[k]);
        return std::string("-");
    };
    std::ostringstream t;
    t << "### The paper's Table 2: " << label << " (scenes/" << scene_file << " to t = " << end_time
      << " s; medians over the " << measured << " steps from " << from_fluid << " fluid particles on; " << r.steps
      << " steps, top speed " << r.top_speed << " m/s, peak density error " << 100 * r.error_max << "%)\n\n"
      << "| | FP | SBP | IBP | GP | pcisph ms | lsm ms | coupling ms | solid_contact ms | neighbors ms | "
         "solid_volumes ms | ms/step | surface ms |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n"
      << "| this product, " << o.backend << " | " << fluid << " (at the end) | " << counts.by_type[kSurfaceBoundary]
      << " | " << counts.by_type[kInnerBoundary] << " | " << counts.by_type[kGeometry] << " | " << stage("pcisph")
      << " | " << stage("lsm") << " | " << stage("coupling") << " | " << stage("solid_contact") << " | "
      << stage("neighbors") << " | " << stage("solid_volumes") << " | " << median_text(step_ms) << " | "
      << median_text(surface_ms) << " (field " << median_text(field_ms) << ") |\n"
      << paper_row;
    return t.str() + "\nThe paper's coupling column is its coupling forces and their distribution (this product's "
                     "`coupling`); where it counts the velocity-position correction (`solid_contact` here) it does not "
                     "say. " + note + " This product's surface ms is one mesh of the fluid's surface at "
                     "output.surface.voxel " + format_number(scene.surface_voxel) + " r0 (the colour field and OpenVDB's "
                     "mesher; the particles' download and the OBJ's writing aside, as in summary.json), median over " +
           std::to_string(surface_ms.size()) + " meshes at the scene's frame times, the last of " +
           std::to_string(triangles) + " triangles; the paper's resolution is not given.\n\n";
}


// One run of scenes/thrown_cube.json with `overrides` to `end_time`, or to the guard that stops it
// (docs/solver.md, "Guards"): how it ended, its steps and seconds, the fluid's top speed, and at
// the end the fastest IBP and the object's centre height.
struct ExtremeRun {
    std::string ended = "ran";
    long steps = 0, fluid = 0;
    double seconds = 0, top_fluid = 0, fastest_ibp = 0, centre = 0;
};
ExtremeRun run_thrown_cube(const Options& o, const std::vector<std::string>& overrides, double end_time) {
    const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/thrown_cube.json", overrides);
    const SimulationSetup setup = build_setup(scene);
    const double limit = speed_limit(scene, setup).limit;
    auto sim = make(o, setup);
    ExtremeRun out;
    out.fluid = sim->counts().by_type[kFluid];
    double ms = 0;
    try {
        while (sim->time() < end_time) {
            sim->step();
            const StepReport& rep = sim->last_report();
            ++out.steps;
            ms += rep.total_ms;
            out.top_fluid = std::max(out.top_fluid, rep.max_speed);
            if (!(rep.max_speed < limit) || !(rep.solid_max_speed < limit)) {
                char at[64];
                std::snprintf(at, sizeof at, "runaway at %.3f s", sim->time());
                out.ended = at;
                break;
            }
        }
    } catch (const std::exception& e) {
        out.ended = std::string("stopped: ") + e.what();
    }
    const StepReport& last = sim->last_report();
    out.seconds = ms / 1000;
    out.fastest_ibp = last.solid_max_speed;
    out.centre = last.has("centroid_cube_y") ? last.value("centroid_cube_y") : 0.0;
    return out;
}
}  // namespace

int main(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--backend" && i + 1 < argc) o.backend = argv[++i];
        else if (a == "--threads" && i + 1 < argc) o.threads = std::atoi(argv[++i]);
        else if (a == "--out" && i + 1 < argc) o.out = argv[++i];
        else if (a == "--large") o.large = true;
        else if (a == "--quick") o.quick = true;
        else if (a == "--sections" && i + 1 < argc) {
            std::vector<std::string> chosen;
            std::stringstream list(argv[++i]);
            for (std::string name; std::getline(list, name, ',');) {
                if (!Options{}.wants(name)) {  // the default holds every section
                    std::fprintf(stderr, "bench_fluid: unknown section '%s' (dams, splish, variants, kernels, steps, objects, coupling, extremes, largest_steps, heat, melting, paper)\n",
                                 name.c_str());
                    return 2;
                }
                chosen.push_back(name);
            }
            if (chosen.empty()) {
                std::fprintf(stderr, "bench_fluid: --sections needs at least one of dams, splish, variants, kernels, steps, objects, coupling, extremes, largest_steps, heat, melting, paper\n");
                return 2;
            }
            o.sections = chosen;
        } else {
            std::fprintf(stderr,
                         "usage: bench_fluid [--backend openmp|cuda] [--threads N] [--large] [--quick] "
                         "[--sections dams,splish,variants,kernels,steps,objects,coupling,extremes,largest_steps,heat,melting,paper] [--out FILE]\n");
            return 2;
        }
    }
    if (o.backend != "openmp" && o.backend != "cuda") {
        std::fprintf(stderr, "bench_fluid: unknown backend '%s'\n", o.backend.c_str());
        return 2;
    }
    try {
        const std::string device =
            // A tiny simulation applies --threads before the OpenMP device (thread count) is named.
            o.backend == "cuda" ? cuda_backend_info().description : make(o, dam_break(1000, CellOrdering::kZOrder))->device_name();
        std::fprintf(stderr, "bench_fluid on %s (%s)\n", o.backend.c_str(), device.c_str());
        const int scale = o.quick ? 1 : 3;

        // Each section is printed, and appended to --out, as soon as it is measured, so that a run
        // cut short (a GPU session's deadline) keeps what it finished. The dam breaks come first:
        // they hold the targets (a 1M-particle step on a GPU, bytes per particle).
        auto emit = [&](const std::string& text) {
            std::printf("%s", text.c_str());
            std::fflush(stdout);
            if (!o.out.empty()) {
                std::ofstream file(o.out, std::ios::app);
                file << text;
            }
        };
        emit("Backend: " + o.backend + ", device: " + device + "\n\n" +
             "Medians over the measured steps; 'density error' is the PCISPH average and maximum of "
             "max(rho - rho0, 0)/rho0 at the last iteration (avg: mean over steps; max: over the run).\n\n");

        // Dam breaks are measured once the column is falling and spreading (from t = 0.15 s: the
        // front has moved about 0.1 m), not at rest; except the 1M cases on CPU cores, where the
        // ~300 steps to get there would take minutes, and which start after 2 steps.
        const bool gpu = o.backend == "cuda";
        const double in_motion = 0.15;
        auto warmup_time = [&](long n) { return gpu || n <= 100000 ? in_motion : 0.0; };
        auto measured_steps = [&](long n) { return gpu ? 30 : n >= 1000000 ? 3 * scale : 10 * scale; };
        if (o.wants("dams")) {
            std::vector<Result> dams;
            std::vector<long> sizes = {25000, 100000, 1000000};
            if (o.large) sizes.push_back(4000000);
            for (long n : sizes)
                dams.push_back(measure(o, "dam break " + std::to_string(n / 1000) + "k", dam_break(n, CellOrdering::kZOrder),
                                       measured_steps(n), 2, warmup_time(n)));
            emit("### Dam breaks (0.6 x 0.8 x 0.8 m column, 1.6 x 1.0 x 0.8 m tank, dt = 0.0015 s x r0/0.02 m, "
                 "eta 1%, eta_max 5%; measured from the simulated time 'from t')\n\n" +
                 format_table(dams) + "\n");
        }

        if (o.wants("splish")) {
            std::vector<Result> splish;
            for (const char* spacing : {"0.05", "0.025"}) {
                // A block of edge 1 m - r0 holds the peer's counts: 19³ = 6,859 and 39³ = 59,319.
                const double r0 = std::atof(spacing), edge = 1.0 - r0;
                const std::string side = std::to_string(edge);
                const std::string corner = "[" + side + "," + side + "," + side + "]";
                const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/splishsplash_block.json",
                                               {std::string("fluid.spacing=") + spacing,
                                                "fluid.support_radius=" + std::to_string(2 * r0),
                                                "fluid_blocks.0.max=" + corner});
                // The whole collapse of the block: 1 s of simulated time (300 steps with --quick).
                const int steps = o.quick ? 300 : 1000;
                const int case_steps = std::string(spacing) == "0.05" ? steps : steps / 4;
                SimulationSetup setup = build_setup(scene);
                splish.push_back(measure(o, std::string("SPlisHSPlasH block, r0 ") + spacing + " m", setup, case_steps, 0));
                // The same with the peak density error bounded at 1% (solver.eta_max): the price of
                // matching the peer's peak error.
                setup.params.solver.eta_max = Real(0.01);
                splish.push_back(measure(o, std::string("SPlisHSPlasH block, r0 ") + spacing + " m, eta_max 1%", setup,
                                         case_steps, 0));
            }
            emit("### SPlisHSPlasH comparison (scenes/splishsplash_block.json; dt 0.001 s, eta 1%, >= 3 iterations; "
                 "eta_max 5%, the scenes' default, unless the case says 1%)\n\n" +
                 format_table(splish) +
                 "\nPeer (from the issue, SPlisHSPlasH PCISPH + Akinci, 2 threads on this kind of machine): 17-20 ms "
                 "per step at 0.05 m, 187 ms at 0.025 m; peak density 0.3-1% above rest.\n\n");
        }

        if (o.wants("variants")) {
            std::vector<Result> variants;
            for (CellOrdering ordering : {CellOrdering::kLinear, CellOrdering::kZOrder})
                variants.push_back(measure(o, ordering == CellOrdering::kLinear ? "dam break 100k, linear cells, lists"
                                                                                : "dam break 100k, Z-order cells, lists",
                                           with_lists(dam_break(100000, ordering), true), measured_steps(100000), 2,
                                           warmup_time(100000)));
            // The walls' velocity-position correction off, beside the Z-order row above (it is
            // fused into the prediction and the integration, so it should cost next to nothing).
            {
                SimulationSetup uncorrected = with_lists(dam_break(100000, CellOrdering::kZOrder), true);
                uncorrected.params.boundary.correction = false;
                variants.push_back(measure(o, "dam break 100k, Z-order cells, lists, walls' correction off", uncorrected,
                                           measured_steps(100000), 2, warmup_time(100000)));
            }
            // Gathering from the grid in every iteration: CUDA's default, and its memory layout.
            for (long n : {100000L, 1000000L})
                variants.push_back(measure(o, "dam break " + std::to_string(n / 1000) + "k, Z-order, grid gathers",
                                           with_lists(dam_break(n, CellOrdering::kZOrder), false), measured_steps(n), 2,
                                           warmup_time(n)));
            // The viscosity stage, which the dam breaks above do not run: the paper's μ = 0.05 Pa s.
            {
                SimulationSetup viscous = dam_break(100000, CellOrdering::kZOrder);
                viscous.params.fluid.viscosity = Real(0.05);
                variants.push_back(measure(o, "dam break 100k, Z-order, viscosity 0.05 Pa s", viscous,
                                           measured_steps(100000), 2, warmup_time(100000)));
            }
            emit("### Variants: cell order, neighbour lists or grid gathers, the walls' correction, viscosity\n\n" +
                 format_table(variants) +
                 "\n");
        }

        // The kernel (fluid.kernel), side by side. The cubic spline at h = 2.5 r0 is left out: it
        // throws particles by t = 0.03 s and its step falls to microseconds before the measurement
        // starts (docs/solver.md, "Kernels").
        if (o.wants("kernels")) {
            struct KernelCase {
                const char* name;
                KernelKind kernel;
                Real support_in_r0;
            };
            std::vector<Result> kernels;
            for (const KernelCase c : {KernelCase{"cubic spline, h = 2 r0", KernelKind::kCubicSpline, 2},
                                       KernelCase{"Wendland C2, h = 2 r0", KernelKind::kWendlandC2, 2},
                                       KernelCase{"Wendland C2, h = 2.5 r0", KernelKind::kWendlandC2, 2.5}})
                kernels.push_back(measure(o, std::string("dam break 100k, ") + c.name,
                                          with_lists(dam_break(100000, CellOrdering::kZOrder, c.kernel, c.support_in_r0),
                                                     true),
                                          measured_steps(100000), 2, warmup_time(100000)));
            emit("### Kernels (fluid.kernel), Z-order cells, neighbour lists\n\n" + format_table(kernels) + "\n");
        }
        // The time step's trade, whole runs of the default scene (the CLI's setup, bitwise): its
        // own CFL 0.4 under 1.5 ms first, the reference; then CFL 0.4 to 1 under the paper's
        // 30 ms (the larger numbers need the retries of steps that diverge or run out of
        // iterations).
        if (o.wants("steps")) {
            const double end_time = o.quick ? 0.5 : 1.5;
            std::vector<WholeRun> runs;
            SolverParams solver;  // the scene's tolerances, for the title
            for (const StepCase c : {StepCase{"0.4", "0.0015"}, StepCase{"0.4", "0.03"}, StepCase{"0.6", "0.03"},
                                     StepCase{"0.8", "0.03"}, StepCase{"1", "0.03"}}) {
                const Scene scene = scene_at_step("dam_break.json", c);
                solver = scene.params.solver;
                runs.push_back(run_whole(o, c.name(), build_setup(scene), end_time));
            }
            char title[200];
            std::snprintf(title, sizeof title,
                          "### Time step (scenes/dam_break.json, %ld fluid particles, to t = %.1f s; eta %g%%, "
                          "eta_max %g%%)\n\n",
                          runs.front().fluid, end_time, 100 * double(solver.eta), 100 * double(solver.eta_max));
            emit(title + format_whole_runs(runs, end_time) +
                 "\n's to the end' sums the stages' times over every step (no output written).\n\n");
        }
        // Static mesh objects (scenes/dam_break_cylinder.json): the default scene with a cylinder
        // 0.2 m across standing in the surge's path, 0.5 m past the column. Whole runs with and
        // without the object's correction (its distance grid dropped from the same setup),
        // counting after every step the fluid inside the cylinder by that grid's signed distance.
        if (o.wants("objects")) {
            const double end_time = o.quick ? 0.6 : 1.0;
            std::vector<WholeRun> runs;
            for (const StepCase c : {StepCase{"0.4", "0.0015"}, StepCase{"1", "0.03"}}) {
                const SimulationSetup with = build_setup(scene_at_step("dam_break_cylinder.json", c));
                const ContactField field = with.params.boundary.static_objects.at(0);
                const std::vector<Real>& distances = with.params.boundary.static_object_distances;
                HostParticles particles;
                const StepObserver count_inside = [&](Simulation& sim, WholeRun& r) {
                    sim.download(particles);
                    long inside = 0;
                    for (std::size_t i = 0; i < particles.type.size(); ++i) {
                        Real d = 0;
                        Vec3 gradient{0, 0, 0};
                        if (particles.type[i] != kFluid ||
                            !field.field.sample(View<const Real>{distances.data(), distances.size()},
                                                particles.position[i], d, gradient))
                            continue;
                        inside += d < 0;
                        r.closest = std::min(r.closest, double(d));
                    }
                    r.most_inside = std::max(r.most_inside, inside);
                };
                SimulationSetup without = with;
                without.params.boundary.static_objects.clear();
                without.params.boundary.static_object_distances.clear();
                runs.push_back(run_whole(o, c.name() + ", object's correction on", with, end_time, count_inside));
                runs.push_back(run_whole(o, c.name() + ", object's correction off", without, end_time, count_inside));
            }
            std::ostringstream t;
            t << "### Static mesh objects (scenes/dam_break_cylinder.json: the default dam break and a static cylinder, r 0.1 m, at x = 1.1 m; to t = "
              << end_time << " s)\n\n"
              << "| case | steps | halvings of a step | iterations | s to the end | ms/step | peak density error | "
                 "top speed m/s | most fluid inside the cylinder | closest to its surface, r0 |\n"
                 "|---|---|---|---|---|---|---|---|---|---|\n";
            const double r0 = 0.02;
            char cell[320];
            for (const WholeRun& r : runs) {
                std::snprintf(cell, sizeof cell, "| %s | %ld | %ld | %ld | %.2f | %.2f | %.2f%% | %.2f | %ld | %.2f |\n",
                              r.name.c_str(), r.steps, r.halvings, r.iterations, r.ms_total / 1000,
                              r.ms_total / double(r.steps), 100 * r.error_max, r.top_speed, r.most_inside,
                              r.closest / r0);
                t << cell;
            }
            emit(t.str() + "\n's to the end' sums the stages' times over every step (no output written; the "
                           "particles are read back after each step to count, outside the timed stages).\n\n");
        }
        // Coupling with moving solids (scenes/floating_boxes.json): the same pool and objects
        // two-way, with and without the correction against them; the median of each coupling
        // stage per step next to the whole step's.
        if (o.wants("coupling")) {
            const double end_time = o.quick ? 0.3 : 0.5;
            struct CouplingCase {
                const char* name;
                std::vector<std::string> overrides;
            };
            // (One-way, the boxes get no buoyancy and sink onto the fluid, which the run's density
            // guard stops at 0.15 s: not a case to time.)
            const std::vector<CouplingCase> cases = {
                {"two-way", {"coupling.two_way=true", "coupling.correction=false"}},
                {"two-way, correction", {"coupling.two_way=true", "coupling.correction=true"}},
                {"two-way, correction, strong off", {"coupling.two_way=true", "coupling.correction=true", "coupling.strong=false"}}};
            std::ostringstream t;
            long fluid = 0;
            std::string rows;
            for (const CouplingCase& c : cases) {
                const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/floating_boxes.json", c.overrides);
                std::vector<double> step_ms, coupling_ms, contact_ms;
                const StepObserver stage_times = [&](Simulation& sim, WholeRun&) {
                    const std::vector<std::string> names = sim.stage_names();
                    const StepReport& rep = sim.last_report();
                    step_ms.push_back(rep.total_ms);
                    for (std::size_t k = 0; k < names.size() && k < rep.stage_ms.size(); ++k) {
                        if (names[k] == "coupling") coupling_ms.push_back(rep.stage_ms[k]);
                        if (names[k] == "solid_contact") contact_ms.push_back(rep.stage_ms[k]);
                    }
                };
                const WholeRun r = run_whole(o, c.name, build_setup(scene), end_time, stage_times);
                fluid = r.fluid;
                char cell[320];
                std::snprintf(cell, sizeof cell, "| %s | %ld | %ld | %.2f | %s | %s | %s | %.2f | %.3f |\n", c.name,
                              r.steps, r.halvings, r.ms_total / 1000, median_text(step_ms).c_str(),
                              median_text(coupling_ms).c_str(), median_text(contact_ms).c_str(), r.top_speed,
                              r.kinetic_energy.back());
                rows += cell;
            }
            t << "### Coupling with moving solids (scenes/floating_boxes.json: " << fluid
              << " fluid particles, two rigid boxes and an elastic cube; to t = " << end_time << " s)\n\n"
              << "| case | steps | halvings of a step | s to the end | ms/step, median | coupling ms, median | "
                 "solid_contact ms, median | top speed m/s | fluid kinetic energy at the end, J |\n"
                 "|---|---|---|---|---|---|---|---|---|\n"
              << rows;
            emit(t.str() + "\nThe paper's Table 2 gives 5.3 ms of coupling per step for its Fig. 8 (25k fluid "
                           "particles, 3.5k SBPs, 6k IBPs) on a GTX 690.\n\n");
        }
        // The extremes (scenes/thrown_cube.json): Table 1's range of solid densities thrown into
        // a pool, each run to its end or to the guard that stops it (docs/solver.md, "Guards").
        if (o.wants("extremes")) {
            const double end_time = o.quick ? 0.6 : 1.5;
            std::string rows;
            long fluid = 0;
            // Rigid cubes with and without coupling.strong side by side; the elastic cubes with it
            // (their defaults: docs/coupling.md, "An elastic object answers as one body").
            struct ExtremeKind {
                const char* kind;
                const char* strong;
            };
            for (const ExtremeKind k : {ExtremeKind{"rigid", "true"}, ExtremeKind{"rigid", "false"}, ExtremeKind{"elastic", "true"}})
                for (const char* density : {"100", "500", "2000", "10000"})
                    for (const char* cfl : {"0.4", "1"}) {
                        const char* kind = k.kind;
                        const ExtremeRun r = run_thrown_cube(
                            o,
                            {std::string("objects.0.kind=\"") + kind + "\"", std::string("objects.0.density=") + density,
                             std::string("solver.cfl_number=") + cfl, std::string("coupling.strong=") + k.strong},
                            end_time);
                        fluid = r.fluid;
                        char cell[400];
                        const char* strong = std::string(kind) == "rigid" ? (std::string(k.strong) == "true" ? "on" : "off") : "-";
                        std::snprintf(cell, sizeof cell, "| %s | %s | %s | %s | %s | %ld | %.2f | %.2f | %.3f | %.3f |\n", kind,
                                      strong, density, cfl, r.ended.c_str(), r.steps, r.seconds, r.top_fluid, r.fastest_ibp,
                                      r.centre);
                        rows += cell;
                        std::fprintf(stderr, "  extremes %-8s strong %-3s %6s kg/m3 CFL %-4s %s, %ld steps\n", kind, strong,
                                     density, cfl, r.ended.c_str(), r.steps);
                    }
            std::ostringstream t;
            t << "### The extremes (scenes/thrown_cube.json: " << fluid << " fluid particles, a 0.12 m cube thrown down "
              << "at 5 m/s, steps up to 30 ms; to t = " << end_time << " s)\n\n"
              << "| kind | coupling.strong | kg/m3 | CFL | end | steps | s | top fluid speed m/s | fastest IBP at the end m/s | cube's "
                 "centre height at the end m |\n|---|---|---|---|---|---|---|---|---|---|\n"
              << rows;
            emit(t.str() + "\nOn the floor the cube's centre is at 0.06 m, on the walls' film (coupling.wall_film) 0.09 m; floating, 0.25 m less its draft plus 0.06 m.\n\n");
            // A flat body landing flat: the same pool, a box 0.24 x 0.08 x 0.24 m let go from rest
            // under water, its broad face down, onto the film over the floor (docs/validation.md,
            // "A flat body landing flat").
            std::string flat_rows;
            for (const ExtremeKind k : {ExtremeKind{"rigid", "true"}, ExtremeKind{"rigid", "false"}, ExtremeKind{"elastic", "true"}})
                for (const char* density : {"2000", "3000", "10000"})
                    for (const char* cfl : {"0.4", "1"}) {
                        const ExtremeRun r = run_thrown_cube(
                            o,
                            {"objects.0.mesh.procedural=\"box:x=0.24,y=0.08,z=0.24\"", "objects.0.transform.translation=[0.3,0.15,0.2]",
                             "objects.0.velocity=[0,0,0]", std::string("objects.0.kind=\"") + k.kind + "\"",
                             std::string("objects.0.density=") + density, std::string("solver.cfl_number=") + cfl,
                             std::string("coupling.strong=") + k.strong},
                            end_time);
                        char cell[400];
                        const char* strong = std::string(k.kind) == "rigid" ? (std::string(k.strong) == "true" ? "on" : "off") : "-";
                        std::snprintf(cell, sizeof cell, "| %s | %s | %s | %s | %s | %ld | %.2f | %.2f | %.3f | %.3f |\n", k.kind,
                                      strong, density, cfl, r.ended.c_str(), r.steps, r.seconds, r.top_fluid, r.fastest_ibp,
                                      r.centre);
                        flat_rows += cell;
                        std::fprintf(stderr, "  flat landing %-8s strong %-3s %6s kg/m3 CFL %-4s %s, %ld steps\n", k.kind, strong,
                                     density, cfl, r.ended.c_str(), r.steps);
                    }
            std::ostringstream f;
            f << "### A flat body landing flat (scenes/thrown_cube.json with a box 0.24 x 0.08 x 0.24 m let go from rest, its "
                 "centre 0.15 m up; steps up to 30 ms; to t = "
              << end_time << " s)\n\n"
              << "| kind | coupling.strong | kg/m3 | CFL | end | steps | s | top fluid speed m/s | fastest IBP at the end m/s | box's "
                 "centre height at the end m |\n|---|---|---|---|---|---|---|---|---|---|\n"
              << flat_rows;
            emit(f.str() + "\nOn the floor the box's centre is at 0.04 m, on the walls' film (coupling.wall_film) 0.07 m.\n\n");
        }
        // The largest steps (scenes/thrown_cube.json): each case of the extremes at rising CFL
        // numbers, judged as tests/core/test_extremes.cpp judges its cases (ran to the end, nothing
        // lost, no fluid within r0/2 of an IBP at the end, the fluid's and the IBPs' kinetic and
        // potential energy never above their start by 0.1% (sampled every 10 steps), the fastest
        // IBP under 0.5 m/s at the end, a cube heavier than water on the floor within r0/2).
        if (o.wants("largest_steps")) {
            const double end_time = o.quick ? 0.6 : 1.5;
            // A run's settings: a CFL number (steps up to the scene's 30 ms) or a fixed step.
            struct StepSetting {
                const char* label;
                std::vector<std::string> overrides;
            };
            const std::vector<StepSetting> cfl_settings = {{"0.4", {"solver.cfl_number=0.4"}},
                                                           {"0.7", {"solver.cfl_number=0.7"}},
                                                           {"1", {"solver.cfl_number=1"}}};
            std::vector<StepSetting> fixed_settings;
            for (const char* ms : {"1", "2", "4", "8", "16", "30"})
                fixed_settings.push_back({ms, {"solver.dt_mode=\"fixed\"", std::string("solver.dt=") + std::to_string(std::atof(ms) / 1000)}});
            std::string rows;
            for (const char* kind : {"rigid", "elastic"})
                for (const char* density : {"100", "500", "2000", "10000"}) {
                    std::string cells;
                    for (const std::vector<StepSetting>* settings : {&cfl_settings, static_cast<const std::vector<StepSetting>*>(&fixed_settings)}) {
                    std::string holds = "none", fails = "-";
                    for (const StepSetting& setting : *settings) {
                        std::vector<std::string> overrides = {std::string("objects.0.kind=\"") + kind + "\"",
                                                              std::string("objects.0.density=") + density};
                        overrides.insert(overrides.end(), setting.overrides.begin(), setting.overrides.end());
                        const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/thrown_cube.json", overrides);
                        const SimulationSetup setup = build_setup(scene);
                        const FluidParams& fp = setup.params.fluid;
                        const double fluid_mass =
                            fp.rest_density / prototype_sums(CubicSpline3D::with_support(fp.support_radius), fp.spacing, 3).sum_W;
                        const SolidSetup& cube = setup.solids.front();
                        const double ibp_mass = double(cube.density) * cube.spacing * cube.spacing * cube.spacing;
                        const double g = -setup.params.gravity.y;
                        HostParticles h;
                        const auto energy = [&] {
                            double e = 0;
                            for (std::size_t i = 0; i < h.type.size(); ++i) {
                                const double m = h.type[i] == kFluid ? fluid_mass : h.type[i] == kInnerBoundary ? ibp_mass : 0;
                                e += m * (0.5 * double(norm2(h.velocity[i])) + g * double(h.position[i].y));
                            }
                            return e;
                        };
                        const double limit = speed_limit(scene, setup).limit;
                        auto sim = make(o, setup);
                        sim->download(h);
                        const double e0 = energy();
                        double gain = 0, top_dt = 0;
                        std::string failed;
                        try {
                            for (long step = 1; sim->time() < end_time; ++step) {
                                sim->step();
                                const StepReport& rep = sim->last_report();
                                top_dt = std::max(top_dt, rep.dt);
                                if (!(rep.max_speed < limit) || !(rep.solid_max_speed < limit)) {
                                    failed = "runaway";
                                    break;
                                }
                                if (step % 10 == 0) {
                                    sim->download(h);
                                    gain = std::max(gain, (energy() - e0) / std::fabs(e0));
                                }
                            }
                        } catch (const std::exception& e) {
                            failed = "stopped";
                        }
                        if (failed.empty()) {
                            sim->download(h);
                            gain = std::max(gain, (energy() - e0) / std::fabs(e0));
                            std::vector<Vec3> ibps;
                            double centre = 0;
                            for (std::size_t i = 0; i < h.type.size(); ++i)
                                if (h.type[i] == kInnerBoundary) {
                                    ibps.push_back(h.position[i]);
                                    centre += h.position[i].y;
                                }
                            centre /= double(ibps.size());
                            long inside = 0;
                            const Real r0 = fp.spacing;
                            for (std::size_t i = 0; i < h.type.size(); ++i)
                                if (h.type[i] == kFluid)
                                    for (const Vec3& b : ibps)
                                        if (norm2(h.position[i] - b) < Real(0.25) * r0 * r0) {
                                            ++inside;
                                            break;
                                        }
                            const StepReport& last = sim->last_report();
                            // On the floor: half the cube's 0.12 m, plus the walls' film (coupling.wall_film, 1.5 r0).
                            const double film = setup.params.coupling.wall_film ? 1.5 * r0 : 0.0;
                            const double floor_centre = double(cube.density) > fp.rest_density ? 0.06 + film : centre;
                            char why[160] = "";
                            if (last.lost_particles > 0) std::snprintf(why, sizeof why, "%ld lost", last.lost_particles);
                            else if (inside > 0) std::snprintf(why, sizeof why, "%ld fluid inside", inside);
                            else if (gain > 1e-3) std::snprintf(why, sizeof why, "energy gained %.1f%%", 100 * gain);
                            else if (!(last.solid_max_speed < 0.5)) std::snprintf(why, sizeof why, "still at %.2f m/s", last.solid_max_speed);
                            else if (std::fabs(centre - floor_centre) > 0.5 * r0) std::snprintf(why, sizeof why, "%.3f m off the floor", centre - floor_centre);
                            failed = why;
                        }
                        const bool cfl = settings == &cfl_settings;
                        std::fprintf(stderr, "  largest steps %-8s %6s kg/m3 %s %-4s %s (largest step %.1f ms)\n", kind, density,
                                     cfl ? "CFL" : "fixed ms", setting.label, failed.empty() ? "holds" : failed.c_str(), 1000 * top_dt);
                        if (!failed.empty()) {
                            fails = std::string(setting.label) + (cfl ? "" : " ms") + ": " + failed;
                            break;
                        }
                        char held[64];
                        if (cfl) std::snprintf(held, sizeof held, "%s (steps up to %.1f ms)", setting.label, 1000 * top_dt);
                        else std::snprintf(held, sizeof held, "%s ms", setting.label);
                        holds = held;
                    }
                    cells += " | " + holds + " | " + fails;
                    }
                    rows += std::string("| ") + kind + " | " + density + cells + " |\n";
                }
            emit("### The largest steps (scenes/thrown_cube.json, a 0.12 m cube thrown down at 5 m/s; to t = " +
                 std::to_string(end_time).substr(0, 3) +
                 " s)\n\n| kind | kg/m3 | holds up to CFL (steps capped at 30 ms) | the first CFL that fails | holds up to the fixed step | "
                 "the first fixed step that fails |\n|---|---|---|---|---|---|\n" +
                 rows + "\nA case holds when it runs to the end with nothing lost, no fluid inside the cube, no energy gained, the cube at rest and, "
                        "heavier than water, on the floor (on the walls' film where coupling.wall_film keeps it); each column stops at the first setting that fails.\n\n");
        }
        // Heat conduction (scenes/warm_jelly.json): the stage's cost against the step's, as the
        // Fourier number, and with it the explicit sub-steps (algorithms/heat.hpp), grows.
        if (o.wants("heat")) {
            const double end_time = o.quick ? 0.2 : 0.5;
            struct HeatCase {
                std::string name;
                std::vector<std::string> overrides;
            };
            auto scaled = [](double factor) {
                char fluid[64], jelly[64], block[64];
                std::snprintf(fluid, sizeof fluid, "fluid.thermal_diffusivity=%g", 0.002 * factor);
                std::snprintf(jelly, sizeof jelly, "objects.0.thermal_diffusivity=%g", 0.004 * factor);
                std::snprintf(block, sizeof block, "objects.1.thermal_diffusivity=%g", 0.01 * factor);
                return std::vector<std::string>{fluid, jelly, block};
            };
            const std::vector<HeatCase> cases = {{"heat off", {"heat.enabled=false"}},
                                                 {"the scene's diffusivities", scaled(1)},
                                                 {"5 times them", scaled(5)},
                                                 {"25 times them", scaled(25)}};
            std::string rows;
            long fluid = 0;
            for (const HeatCase& c : cases) {
                const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/warm_jelly.json", c.overrides);
                std::vector<double> step_ms, heat_ms, pcisph_ms, substeps;
                const StepObserver stage_times = [&](Simulation& sim, WholeRun&) {
                    const std::vector<std::string> names = sim.stage_names();
                    const StepReport& rep = sim.last_report();
                    step_ms.push_back(rep.total_ms);
                    if (rep.has("heat_substeps") && rep.value("heat_substeps") > 0)
                        substeps.push_back(int(rep.value("heat_substeps")));
                    for (std::size_t k = 0; k < names.size() && k < rep.stage_ms.size(); ++k) {
                        if (names[k] == "heat") heat_ms.push_back(rep.stage_ms[k]);
                        if (names[k] == "pcisph") pcisph_ms.push_back(rep.stage_ms[k]);
                    }
                };
                const WholeRun r = run_whole(o, c.name, build_setup(scene), end_time, stage_times);
                fluid = r.fluid;
                const double fourier = scene.params.heat.enabled
                                           ? scene.largest_heat_diffusivity() * double(scene.params.solver.dt) /
                                                 (double(scene.params.fluid.spacing) * double(scene.params.fluid.spacing))
                                           : 0.0;
                char cell[320];
                std::snprintf(cell, sizeof cell, "| %s | %.3g | %ld | %.2f | %s | %s | %s | %s |\n", c.name.c_str(),
                              fourier, r.steps, r.ms_total / 1000, median_text(step_ms).c_str(),
                              median_text(pcisph_ms).c_str(), median_text(heat_ms).c_str(),
                              median_text(substeps).c_str());
                rows += cell;
            }
            std::ostringstream t;
            t << "### Heat conduction (scenes/warm_jelly.json: " << fluid
              << " fluid particles, an elastic cube and a rigid block; to t = " << end_time << " s)\n\n"
              << "| case | Fourier number at the largest step | steps | s to the end | ms/step, median | pcisph ms, "
                 "median | heat ms, median | heat sub-steps, median |\n|---|---|---|---|---|---|---|---|\n"
              << rows;
            emit(t.str() + "\nThe paper's Table 2 gives no separate figure for heat; its melting scenes (Fig. 11) "
                           "take 87 and 129 ms per step in all on a GTX 690.\n\n");
        }
        // Melting (scenes/melting_ice.json): what the phase change costs, on the steps where
        // something melts (two read-backs, the exposure and the regions' rebuild) and elsewhere.
        if (o.wants("melting")) {
            const double end_time = o.quick ? 0.5 : 1.5;
            struct MeltCase {
                std::string name;
                std::vector<std::string> overrides;
            };
            const std::vector<MeltCase> cases = {
                {"0.14 m cube (the scene's)", {}},
                {"without latent heat", {"objects.0.latent_heat=0"}},
                // A lattice of 8,000 melting a layer a step, no fluid to start with: the phase
                // change's own cost at the size of the paper's Fig. 11 cubes.
                {"0.4 m cube 30 C above its melting point, alone",
                 {"fluid_blocks=[]", "gravity=[0,0,0]", "domain.max=[0.8,0.8,0.8]",
                  "objects.0.mesh.procedural=box:x=0.4,y=0.4,z=0.4", "objects.0.transform.translation=[0.4,0.4,0.4]",
                  "objects.0.temperature=30", "objects.0.latent_heat=0"}}};
            std::string rows;
            for (const MeltCase& c : cases) {
                const Scene scene = load_scene(std::string(MW_SOURCE_DIR) + "/scenes/melting_ice.json", c.overrides);
                const SimulationSetup setup = build_setup(scene);
                const long lattice = long(setup.solids.at(0).ibp.size());
                std::vector<double> step_ms, melt_step_ms, quiet_ms, lsm_ms;
                long melted = 0;
                const StepObserver stage_times = [&](Simulation& sim, WholeRun&) {
                    const std::vector<std::string> names = sim.stage_names();
                    const StepReport& rep = sim.last_report();
                    step_ms.push_back(rep.total_ms);
                    const long melted_total = rep.has("melted") ? long(rep.value("melted")) : 0;
                    const bool melted_now = melted_total > melted;
                    melted = melted_total;
                    for (std::size_t k = 0; k < names.size() && k < rep.stage_ms.size(); ++k) {
                        if (names[k] == "melting") (melted_now ? melt_step_ms : quiet_ms).push_back(rep.stage_ms[k]);
                        if (names[k] == "lsm") lsm_ms.push_back(rep.stage_ms[k]);
                    }
                };
                const WholeRun r = run_whole(o, c.name, setup, end_time, stage_times);
                const double largest = melt_step_ms.empty() ? 0.0 : *std::max_element(melt_step_ms.begin(), melt_step_ms.end());
                char cell[400];
                std::snprintf(cell, sizeof cell, "| %s | %ld | %ld | %ld | %ld | %s | %s | %s | %.2f | %s |\n", c.name.c_str(),
                              r.fluid, lattice, melted, r.steps, median_text(step_ms).c_str(), median_text(lsm_ms).c_str(),
                              median_text(melt_step_ms).c_str(), largest, median_text(quiet_ms).c_str());
                rows += cell;
            }
            std::ostringstream t;
            t << "### Melting (scenes/melting_ice.json: an ice cube in water at 60 C; to t = " << end_time << " s)\n\n"
              << "| case | fluid particles at the start | lattice particles | melted | steps | ms/step, median | lsm ms, "
                 "median | melting ms on steps that melted, median | ... largest | melting ms on the other steps, median |\n"
                 "|---|---|---|---|---|---|---|---|---|---|\n"
              << rows;
            emit(t.str() + "\nThe paper's Table 2 gives 87 ms per step in all for its melting ice cube (Fig. 11a: 40.5k "
                           "fluid particles, 3.6k SBPs, 16.3k IBPs) on a GTX 690, with no separate figure for the phase "
                           "change.\n\n");
        }
        // The paper's Table 2 (docs/method.md), the rows the product can run: the stages' medians
        // once the stream has brought most of the paper's fluid particles.
        if (o.wants("paper")) {
            const std::string mesh = std::string(MW_SOURCE_DIR) + "/../shared/assets/meshes/stanford-bunny.obj";
            if (!std::ifstream(mesh)) {
                emit("### The paper's Table 2: Fig. 8\n\nSkipped: " + mesh + " is missing (shared/assets).\n\n");
            } else {
                emit(table2_row(o, "Fig. 8: stream onto a pinned elastic bunny", "bunny_stream.json", o.quick ? 1.0 : 3.2,
                                o.quick ? 0 : 20000,
                                "| the paper (GTX 690) | 25k | 3.5k | 6k | | 17.3 | 10.1 | 5.3 | | | | 48.1 (with surface) | 15.4 |\n",
                                "Its bunny's GPs are not given."));
            }
            emit(table2_row(o, "Fig. 9: stream into a thin elastic box", "thin_box_pour.json", o.quick ? 0.5 : 1.9,
                            o.quick ? 0 : 10000,
                            "| the paper (GTX 690) | 15k | 5k | 3k | | 12.4 | 7.8 | 6.3 | | | | 38.8 (with surface) | 12.3 |\n",
                            "Its walls are 2 r0 thick, a layer of SBPs on each face and two of IBPs between; its step "
                            "is fixed at 1 ms (docs/lsm.md, 'Light thin objects'); the paper's is not given."));
            emit(table2_row(o, "Fig. 10: stream onto a cloth", "cloth_stream.json", o.quick ? 0.5 : 1.9, o.quick ? 0 : 10000,
                            "| the paper (GTX 690) | 15k | 2.5k | – | | 12.5 | 7.0 | 6.2 | | | | 38.1 (with surface) | 12.4 |\n",
                            "The paper's cloth is 300 kg/m3, this one 1000 kg/m3 (docs/cloth.md); its nodes are the "
                            "IBP column, and the paper's cloth has its vertices as SBPs only."));
            emit(table2_row(o, "Fig. 1: a stream down a stair over four hollow objects", "stair_flow.json",
                            o.quick ? 0.3 : 1.5, o.quick ? 0 : 8000,
                            "| the paper (GTX 690) | 894.6k | 27.8k | 51.7k | | 561.5 | 39.5 | 21.4 | | | | 1015.2 (with surface) | 392.8 |\n",
                            "This scene is the paper's at CI size (11k fluid particles released, r0 0.02 m; the paper's "
                            "894.6k is not measured here); its fixed 1 ms step and its limits: docs/contact.md."));
            emit(table2_row(o, "Fig. 11b: four melting cubes under streams", "melting_streams.json", o.quick ? 0.5 : 2.0,
                            o.quick ? 0 : 3600,
                            "| the paper (GTX 690) | 60k | 6.2k | 25.4k | | 46.5 | 33.4 | 14.2 | | | | 129.4 (with surface) | 35.3 |\n",
                            "This scene is the paper's at CI size (0.1 m cubes of 125 lattice particles, 7.2k fluid "
                            "particles released); at the paper's size (0.4 m cubes, 60k) it fails (docs/melting.md, "
                            "'Limits')."));
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_fluid: %s\n", e.what());
        return 1;
    }
    return 0;
}
