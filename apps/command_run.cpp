// `meltwater run [SCENE]`: simulate, writing frames, stats.csv and summary.json into --out.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>

#include "apps/checkpoint_file.hpp"
#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "apps/run_outputs.hpp"
#include "apps/scene_builder.hpp"
#include "apps/speed_limit.hpp"
#include "apps/atomic_file.hpp"
#include "simulation/factory.hpp"
#include "common/errors.hpp"

namespace mw {

namespace {
volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_interrupt(int) { g_interrupted = 1; }

// Ctrl-C, a terminal closing and a polite kill (a job scheduler's time limit) stop the run after
// the current step, with whole stats.csv and summary.json and no partial frame; during set-up,
// before the first step, with nothing written. Installed for the whole command, restored after.
class StopSignals {
   public:
    StopSignals() {
        g_interrupted = 0;
        for (int k = 0; k < kCount; ++k) previous_[k] = std::signal(kSignals[k], on_interrupt);
    }
    ~StopSignals() {
        for (int k = 0; k < kCount; ++k) std::signal(kSignals[k], previous_[k]);
    }
    StopSignals(const StopSignals&) = delete;
    StopSignals& operator=(const StopSignals&) = delete;

   private:
    static constexpr int kCount = 3;
    static constexpr int kSignals[kCount] = {SIGINT, SIGTERM, SIGHUP};
    void (*previous_[kCount])(int);
};

int report_interrupted_setup() {
    std::fprintf(stderr, "meltwater: interrupted during set-up, before the first step; nothing was written\n");
    return 130;
}

// What PCISPH did before a run stopped: the steps integrated after the iteration diverged or ran
// out of iterations (columns diverged and unconverged of stats.csv), or "" if none.
std::string failed_iterations_hint(const StatsTable& stats) {
    std::string hint;
    if (stats.diverged_steps() > 0) hint += "diverged in " + count_of(stats.diverged_steps(), "step");
    if (stats.unconverged_steps() > 0)
        hint += (hint.empty() ? "" : " and ") + std::string("ran out of iterations above its tolerance in ") +
                count_of(stats.unconverged_steps(), "step");
    if (hint.empty()) return hint;
    return "; PCISPH " + hint + " so far (columns diverged and unconverged of stats.csv): use a smaller dt, or "
           "dt_mode \"cfl\"";
}

// The lost-fluid guard's message: the step, how much fluid left, the limit, and the likely cause.
std::string lost_fluid_message(const StepReport& r, long fluid_count, const StatsTable& stats, const Scene& scene) {
    char head[200];
    std::snprintf(head, sizeof head, "step %ld (t = %.6g s): %s of %s (%.3g%%) have left the domain, more than ",
                  r.step, r.time, with_thousands(r.lost_particles).c_str(),
                  count_of(fluid_count, "fluid particle").c_str(), 100.0 * double(r.lost_particles) / double(fluid_count));
    const std::string hint = failed_iterations_hint(stats);
    return head + ("boundary.max_lost_fraction " + format_number(scene.max_lost_fraction)) +
           (!hint.empty() ? hint
                          : std::string("; the fluid leaked through the walls or blew up (see the last frames "
                                        "and stats.csv)"));
}

std::string density_blowup_message(const StepReport& r, const StatsTable& stats, const Scene& scene) {
    char head[200];
    std::snprintf(head, sizeof head,
                  "step %ld (t = %.6g s): the fluid is packed %.3g%% above its rest density, more than ", r.step,
                  r.time, 100.0 * r.density_error_max);
    const std::string hint = failed_iterations_hint(stats);
    return head + ("solver.max_density_error " + format_number(scene.max_density_error)) +
           (!hint.empty() ? hint : std::string("; the run blew up (see the last frames and stats.csv)"));
}

std::string runaway_message(const StepReport& r, const SpeedLimit& limit, const StatsTable& stats) {
    const bool solid = r.solid_max_speed > r.max_speed;
    char head[200];
    std::snprintf(head, sizeof head, "step %ld (t = %.6g s, dt = %.3g s): %s moves at %.4g m/s, more than ", r.step,
                  r.time, r.dt, solid ? "a solid's particle" : "a fluid particle",
                  solid ? r.solid_max_speed : r.max_speed);
    const std::string hint = failed_iterations_hint(stats);
    return head + describe(limit) +
           (!hint.empty() ? hint : std::string("; the run blew up (see the last frames and stats.csv)"));
}

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Whether two paths name the same existing directory.
bool same_directory(const std::string& a, const std::string& b) {
    std::error_code error;
    return std::filesystem::equivalent(a, b, error) && !error;
}
}  // namespace

int command_run(int argc, char** argv) {
    cxxopts::Options options("meltwater run",
                             "Simulate a scene (the built-in 3D dam break when no SCENE is given) and write\n"
                             "frames/particles_NNNNN.vtu, stats.csv and summary.json into the output directory.");
    add_scene_options(options);
    options.add_options()
        ("backend", "auto (CUDA where a GPU is usable; with --resume, the checkpoint's backend where usable), cuda or openmp", cxxopts::value<std::string>()->default_value("auto"), "NAME")
        ("out", "output directory (default results/<scene name>)", cxxopts::value<std::string>(), "DIR")
        ("steps", "run exactly N steps", cxxopts::value<std::string>(), "N")
        ("time", "run to simulated time T seconds (default: the scene's run.end_time)", cxxopts::value<std::string>(), "T")
        ("threads", "OpenMP threads, 1 to 1024 (default: all cores)", cxxopts::value<std::string>(), "N")
        ("checkpoint", "write DIR/checkpoint.mwc when the run ends or is interrupted")
        ("checkpoint-every", "write it every N steps as well (implies --checkpoint)", cxxopts::value<std::string>(), "N")
        ("resume", "continue the run saved in FILE, with its scene (no SCENE, no --set); --time is the "
                   "simulated time to reach, --steps the steps to add; --out defaults to FILE's directory",
         cxxopts::value<std::string>(), "FILE")
        ("q,quiet", "print only the final summary line and errors");
    std::vector<std::string> overrides;
    const cxxopts::ParseResult args = parse_options(options, argc, argv, &overrides);
    if (flag_option(args, "help")) {
        std::printf("%s\n", options.help().c_str());
        return 0;
    }
    if (args.count("steps") && args.count("time")) throw InputError("--steps and --time exclude each other; give one");
    const long end_steps = integer_option(args, "steps", 0);
    if (args.count("steps") && end_steps < 1)
        throw InputError("--steps must be at least 1, got " + std::to_string(end_steps));
    const int threads = threads_option(args);
    const bool quiet = flag_option(args, "quiet");
    const long checkpoint_every = integer_option(args, "checkpoint-every", 0);
    if (args.count("checkpoint-every") && checkpoint_every < 1)
        throw InputError("--checkpoint-every must be at least 1, got " + std::to_string(checkpoint_every));
    const bool checkpoints = flag_option(args, "checkpoint") || checkpoint_every > 0;
    const StopSignals stop_signals;

    // A resumed run takes everything the simulation is built from out of its checkpoint: the
    // scene as the first run resolved it (overrides applied, mesh paths absolute), so that the
    // setup is built exactly as it was.
    std::unique_ptr<Checkpoint> resume;
    std::string resume_path;
    if (args.count("resume")) {
        resume_path = args["resume"].as<std::string>();
        if (args.count("scene") || !overrides.empty())
            throw InputError("--resume continues the checkpoint's own scene: give no SCENE and no --set");
        resume = std::make_unique<Checkpoint>(read_checkpoint(resume_path));
    }
    Scene scene = resume ? resolve_scene(resume->scene, "checkpoint " + resume_path)
                         : scene_from_options(args, overrides);
    const double end_time = number_option(args, "time", scene.end_time);
    // The same bound as run.end_time: 1e300 s would run for ever.
    if (args.count("time") && !(end_time > 0 && end_time <= 1e6))
        throw InputError("--time must be in (0, 1e6] seconds, got " + format_number(end_time));
    if (resume && end_steps == 0 && !(resume->time < end_time * (1 - 1e-9)))
        throw InputError("the checkpoint is at t = " + format_number(resume->time) + " s, already at the end time " +
                         format_number(end_time) + " s; give a later --time, or --steps");
    // A resumed run left on auto continues on the backend that wrote the checkpoint, where that
    // backend is usable here: the backends round differently, and only the same backend continues
    // bitwise (docs/checkpoints.md). A checkpoint naming neither backend leaves auto as it is.
    const std::string requested_backend = args["backend"].as<std::string>();
    const bool saved_backend_usable =
        resume && (resume->backend == "openmp" || (resume->backend == "cuda" && cuda_backend_info().available));
    const std::string backend =
        choose_backend(requested_backend == "auto" && saved_backend_usable ? resume->backend : requested_backend);
    if (threads > 0 && backend != "openmp" && !quiet)
        std::fprintf(stderr, "meltwater: note: --threads applies to the openmp backend only\n");
    std::string checkpoint_dir;  // of the resumed checkpoint
    if (resume) {
        checkpoint_dir = std::filesystem::path(resume_path).parent_path().string();
        if (checkpoint_dir.empty()) checkpoint_dir = ".";
    }
    const std::string out_dir = args.count("out") ? args["out"].as<std::string>()
                                : resume          ? checkpoint_dir
                                                  : "results/" + (scene.name.empty() ? "run" : scene.name);
    if (out_dir.empty()) throw InputError("--out: empty directory name");

    check_host_memory(scene, backend, backend == "openmp");
    // --threads bounds the set-up too: objects are sampled on the host's OpenMP threads.
    if (backend == "openmp") set_host_threads(threads);
    long carved_fluid = 0;
    const SimulationSetup setup = build_setup(scene, &carved_fluid);
    if (g_interrupted) return report_interrupted_setup();
    const SpeedLimit runaway = speed_limit(scene, setup);
    const std::string emitter_warning = emitter_overlap_warning(setup);
    // Before the simulation is built, so that an unwritable --out fails at once; the directories
    // made here are removed again (if still empty) when the run ends before its first step.
    const std::vector<std::string> created = make_directories(out_dir);
    const std::string stats_path = out_dir + "/stats.csv", summary_path = out_dir + "/summary.json";
    std::unique_ptr<Simulation> sim;
    try {
        // stats.csv and summary.json are renamed into place at the end: a directory by those
        // names would only fail then, after the whole run. A file named frames would fail when the
        // frame writer makes its directory, after the simulation (a GPU upload) is built.
        for (const std::string& path : {stats_path, summary_path})
            if (std::filesystem::is_directory(path))
                throw InputError(path + " is a directory; the run writes a file there");
        const std::string frames_path = out_dir + "/frames";
        if (scene.writes_frames() && std::filesystem::exists(frames_path) && !std::filesystem::is_directory(frames_path))
            throw InputError(frames_path + " is a file; the run writes its frames in a directory there");
        sim = create_simulation(setup, backend, threads);
        if (resume) sim->load_state(resume->state);
    } catch (...) {
        remove_created_directories(created);
        throw;
    }
    if (g_interrupted) {
        remove_created_directories(created);
        return report_interrupted_setup();
    }

    // Resumed in its checkpoint's directory, the run continues that directory's frames and
    // stats.csv from the checkpoint on (what the first run wrote after it goes); elsewhere it
    // starts them afresh, its frames numbered on from the checkpoint's.
    const bool continues_directory = resume && same_directory(out_dir, checkpoint_dir);
    const int first_frame = resume ? static_cast<int>(resume->frame_times.size()) : 0;
    remove_earlier_frames(out_dir, continues_directory ? first_frame : 0);
    std::vector<double> frame_times;  // of every frame up to now, for the next checkpoint
    if (resume) frame_times = resume->frame_times;
    std::unique_ptr<FrameWriter> frames;
    if (scene.writes_frames()) {
        frames = std::make_unique<FrameWriter>(out_dir, scene.writes_vtu());
        frames->set_objects(setup.solids);
        if (continues_directory) frames->keep_earlier(frame_times);
    }
    StatsTable stats(sim->stage_names(), sim->last_report().column_names);
    if (continues_directory) stats.keep_earlier_rows(stats_rows_up_to(stats_path, stats.header(), resume->step));

    RunSummary summary;
    summary.backend = sim->backend_name();
    summary.device = sim->device_name();
    summary.threads = threads;
    summary.particles = sim->counts();
    summary.fluid_carved = carved_fluid;
    summary.device_bytes = sim->device_bytes();
    summary.speed_limit = runaway.limit;
    char stop[64];
    if (end_steps > 0) std::snprintf(stop, sizeof stop, "steps %ld", end_steps);
    else std::snprintf(stop, sizeof stop, "time %g s", end_time);
    summary.stop_condition = stop;
    if (resume) {
        summary.resumed_from = resume_path;
        summary.resumed_step = resume->step;
        summary.resumed_time = resume->time;
        summary.simulated_time = resume->time;
    }

    const std::string heat_warning =
        heat_substeps_warning(sim->heat_substeps_needed(double(scene.params.solver.dt)), scene.params.heat.max_substeps);
    for (const std::string& warning : {scene.kernel_warning(), heat_warning, emitter_warning}) {
        if (warning.empty()) continue;
        std::fprintf(stderr, "meltwater: warning: %s\n", warning.c_str());
        summary.warnings.push_back(warning);
    }
    if (!quiet) {
        const ParticleCounts& c = summary.particles;
        // Carving changes how much fluid a scene holds: say so where the counts are given.
        const std::string carved =
            carved_fluid > 0 ? "; " + with_thousands(carved_fluid) + " fluid carved out where solids stand" : "";
        const std::string pending =
            c.by_type[kPending] > 0 ? ", " + with_thousands(c.by_type[kPending]) + " to be emitted" : "";
        std::fprintf(stderr, "meltwater: %s (%s): %s particles (%s fluid%s, %s boundary%s) on %s [%s], %s; output in %s\n",
                     scene.name.empty() ? "scene" : scene.name.c_str(), scene.source.c_str(),
                     with_thousands(c.total()).c_str(), with_thousands(c.by_type[kFluid]).c_str(), pending.c_str(),
                     with_thousands(c.total() - c.by_type[kFluid] - c.by_type[kPending]).c_str(), carved.c_str(),
                     summary.backend.c_str(), summary.device.c_str(), stop, out_dir.c_str());
        if (resume)
            std::fprintf(stderr, "meltwater: resuming from %s: step %ld, t = %.6g s (written on %s)\n",
                         resume_path.c_str(), resume->step, resume->time, resume->backend.c_str());
    }

    const auto wall_start = std::chrono::steady_clock::now();
    auto last_stats_write = wall_start;
    double stats_write_seconds = 0;  // how long the last rewrite of stats.csv took
    HostParticles host;
    int frame_index = first_frame;
    std::vector<double> surface_ms, surface_field_ms;  // per mesh: all of it, and the colour field's part
    FluidSurfacer surfacer(scene.params, scene.surface_voxel, threads);
    auto write_frame = [&]() {
        if (!frames) return;
        sim->download(host);
        frames->write(frame_index, host, sim->time());
        if (scene.writes_surface()) {
            const FluidSurfacer::Surface surface = surfacer.build(*sim, host);
            frames->write_surface(frame_index, surface.mesh);
            surface_ms.push_back(surface.ms);
            surface_field_ms.push_back(surface.field_ms);
            summary.surfaces = static_cast<int>(surface_ms.size());
            summary.surface_ms_median = median_of(surface_ms);
            summary.surface_field_ms_median = median_of(surface_field_ms);
            summary.surface_triangles_last = static_cast<long>(surface.mesh.triangles.size());
        }
        frame_times.push_back(sim->time());
        ++frame_index;
    };
    const double frame_dt = 1.0 / scene.fps;
    double next_frame_time = resume ? resume->next_frame_time : frame_dt;
    // The checkpoint: the state now, with the scene and the frame clock (checkpoint_file.hpp).
    const std::string checkpoint_path = out_dir + "/" + kCheckpointFileName;
    long checkpoint_step = -1;
    auto write_checkpoint_now = [&]() {
        Checkpoint c;
        c.scene = scene.resolved;
        c.backend = summary.backend;
        c.step = sim->last_report().step;
        c.time = sim->time();
        c.frame_times = frame_times;
        c.next_frame_time = next_frame_time;
        sim->save_state(c.state);
        write_checkpoint(checkpoint_path, c);
        checkpoint_step = c.step;
        summary.checkpoint = checkpoint_path;
        summary.checkpoint_step = c.step;
    };

    std::exception_ptr failure;
    bool interrupted = false;
    try {
        if (!resume) write_frame();  // frame 0: the initial state (a resumed run has its frames)
        Progress progress(quiet ? Progress::Mode::kQuiet : Progress::Mode::kAuto, end_steps, end_time,
                          resume ? resume->step : 0, resume ? resume->time : 0.0);
        long steps_done = 0;
        // Stop at the step that reaches end_time (to a relative tolerance, so 0.1 + 0.1 + ... counts).
        while (end_steps > 0 ? steps_done < end_steps : sim->time() < end_time * (1 - 1e-9)) {
            if (g_interrupted) {
                interrupted = true;
                break;
            }
            try {
                sim->step();
            } catch (const DeviceError& e) {
                // A step can still allocate (neighbour lists growing as the flow compresses):
                // say where the run stood and what it held.
                progress.finish();
                throw DeviceError(std::string(e.what()) + " (in step " + std::to_string(steps_done + 1) + "; the " +
                                  with_thousands(long(summary.particles.total())) + " particles held " +
                                  format_bytes(double(summary.device_bytes)) + " before it)");
            } catch (...) {
                progress.finish();
                throw;
            }
            ++steps_done;
            const StepReport& r = sim->last_report();
            stats.add(r);
            summary.steps = steps_done;
            summary.simulated_time = r.time;
            summary.lost_particles = r.lost_particles;
            progress.update(r);
            // Against the fluid there is now: melting objects add to it (the counts are host figures).
            const long fluid_now = sim->counts().by_type[kFluid];
            if (r.lost_particles > scene.max_lost_fraction * double(fluid_now)) {
                progress.finish();
                throw SimulationError(lost_fluid_message(r, fluid_now, stats, scene));
            }
            if (r.density_error_max > scene.max_density_error) {
                progress.finish();
                throw SimulationError(density_blowup_message(r, stats, scene));
            }
            if (runaway.limit > 0 && std::max(r.max_speed, r.solid_max_speed) > runaway.limit) {
                progress.finish();
                throw SimulationError(runaway_message(r, runaway, stats));
            }
            if (r.time >= next_frame_time * (1 - 1e-9)) {
                write_frame();
                // The next frame time after now (a step longer than 1/fps skips frame times).
                next_frame_time = (std::floor(r.time / frame_dt * (1 + 1e-9)) + 1) * frame_dt;
            }
            if (checkpoint_every > 0 && r.step % checkpoint_every == 0) write_checkpoint_now();
            // Keep stats.csv current for a run that dies: every 5 s, or less often once the file
            // is so long that rewriting it would take more than 5% of the run.
            if (seconds_since(last_stats_write) > std::max(5.0, 20 * stats_write_seconds)) {
                const auto write_start = std::chrono::steady_clock::now();
                stats.write(stats_path);
                stats_write_seconds = seconds_since(write_start);
                last_stats_write = std::chrono::steady_clock::now();
            }
        }
        progress.finish();
    } catch (...) {
        failure = std::current_exception();
    }

    // A run that ended or was stopped leaves its checkpoint (one that failed does not: its state
    // is what failed).
    if (!failure && checkpoints && checkpoint_step != sim->last_report().step) {
        try {
            write_checkpoint_now();
        } catch (...) {
            failure = std::current_exception();
        }
    }
    summary.wall_seconds = seconds_since(wall_start);
    summary.frames = frames ? frames->written() : 0;
    if (failure) {
        summary.status = "failed";
        try {
            std::rethrow_exception(failure);
        } catch (const std::exception& e) {
            summary.error = e.what();
        }
    } else if (interrupted) {
        summary.status = "interrupted";
    }
    // Whatever happened, leave whole stats.csv and summary.json behind.
    bool recorded = true;
    try {
        stats.write(stats_path);
        write_summary(summary_path, summary, stats, scene);
    } catch (const std::exception& e) {
        if (!failure) throw;
        recorded = false;
        std::fprintf(stderr, "meltwater: error: could not record the failure: %s\n", e.what());
    }
    if (failure) {
        std::fprintf(stderr, "meltwater: stopped after %s at t=%.4g s; %s%s kept in %s\n",
                     count_of(summary.steps, "step").c_str(), summary.simulated_time,
                     count_of(summary.frames, "frame").c_str(), recorded ? ", stats.csv and summary.json" : "",
                     out_dir.c_str());
        std::rethrow_exception(failure);
    }

    if (stats.retried_steps() > 0 && !quiet)
        std::fprintf(stderr,
                     "meltwater: note: %s taken again at a smaller dt because PCISPH diverged or ran out of "
                     "iterations (column dt_retries of stats.csv; docs/solver.md, \"Time step\")\n",
                     (count_of(stats.retried_steps(), "step") + (stats.retried_steps() == 1 ? " was" : " were")).c_str());
    if (stats.diverged_steps() > 0)
        std::fprintf(stderr,
                     "meltwater: warning: in %s PCISPH diverged and the step was integrated anyway (column "
                     "diverged of stats.csv); use a smaller dt, or dt_mode \"cfl\" with solver.eta_max\n",
                     count_of(stats.diverged_steps(), "step").c_str());
    if (stats.unconverged_steps() > 0)
        std::fprintf(stderr,
                     "meltwater: warning: in %s PCISPH ran out of iterations (solver.max_iterations %d) above its "
                     "tolerance and the step was integrated anyway (column unconverged of stats.csv)%s\n",
                     count_of(stats.unconverged_steps(), "step").c_str(), scene.params.solver.max_iterations,
                     scene.params.solver.dt_mode == TimeStepMode::kCfl
                         ? "; halving the step (up to six times) did not rescue them: raise solver.max_iterations, or "
                           "loosen solver.eta or solver.eta_max"
                         : "; use a smaller dt, more iterations, or dt_mode \"cfl\"");
    if (summary.lost_particles > 0)
        std::fprintf(stderr, "meltwater: warning: %s left the domain (column lost_particles of stats.csv)\n",
                     count_of(summary.lost_particles, "fluid particle").c_str());
    std::error_code ec;
    const std::string shown = std::filesystem::absolute(out_dir, ec).lexically_normal().string();
    // The fluid's figures mean nothing in a scene without fluid (all zero): say so instead.
    char fluid_figures[160] = "no fluid";
    if (summary.particles.by_type[kFluid] > 0 || stats.has_column("melted") || stats.has_column("emitted"))
        std::snprintf(fluid_figures, sizeof fluid_figures, "density error avg %.3g%% max %.3g%%, %.1f iterations/step",
                      100 * stats.density_error_avg(), 100 * stats.density_error_max(), stats.iterations_avg());
    std::printf("meltwater: %s %s to t=%.4g s in %.1f s (%.1f ms/step median, %s)\n",
                interrupted ? "interrupted after" : "ran", count_of(summary.steps, "step").c_str(),
                summary.simulated_time, summary.wall_seconds,
                stats.median_total_ms(), fluid_figures);
    const std::string surfaces =
        summary.surfaces > 0 ? " and " + count_of(summary.surfaces, "surface") + " (" +
                                   format_number(summary.surface_ms_median) + " ms each)"
                             : "";
    std::printf("meltwater: results in %s (%s%s in frames/, stats.csv, summary.json%s)\n",
                ec ? out_dir.c_str() : shown.c_str(), count_of(summary.frames, "frame").c_str(), surfaces.c_str(),
                summary.checkpoint.empty() ? "" : ", checkpoint.mwc");
    if (!summary.checkpoint.empty() && !quiet)
        std::fprintf(stderr, "meltwater: checkpoint at step %ld (t = %.6g s); continue with: meltwater run --resume %s "
                     "--time T\n", summary.checkpoint_step, summary.simulated_time, summary.checkpoint.c_str());
    std::fflush(stdout);
    return interrupted ? 130 : 0;
}

}  // namespace mw
