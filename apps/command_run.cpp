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
#include "apps/fluid_inside_objects.hpp"
#include "apps/frame_writer.hpp"
#include "apps/preview_picture.hpp"
#include "apps/run_guards.hpp"
#include "apps/run_outputs.hpp"
#include "apps/scene_builder.hpp"
#include "apps/speed_limit.hpp"
#include "apps/atomic_file.hpp"
#include "surface/fluid_surface.hpp"
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

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Whether two paths name the same existing directory.
bool same_directory(const std::string& a, const std::string& b) {
    std::error_code error;
    return std::filesystem::equivalent(a, b, error) && !error;
}
}  // namespace

namespace {

// The command line of `run`, read and checked.
struct RunOptions {
    std::vector<std::string> overrides;
    long end_steps = 0;  // 0: run to a time
    int threads = 0;
    bool quiet = false;
    long checkpoint_every = 0;
    bool checkpoints = false;
    std::string resume_path;  // "" for a fresh run
    std::string requested_backend, out;
    bool has_scene = false, has_time = false, has_out = false;
    cxxopts::ParseResult args;
};

cxxopts::Options run_options() {
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
    return options;
}

RunOptions read_run_options(cxxopts::Options& options, int argc, char** argv) {
    RunOptions o;
    o.args = parse_options(options, argc, argv, &o.overrides);
    const cxxopts::ParseResult& args = o.args;
    if (flag_option(args, "help")) return o;
    if (args.count("steps") && args.count("time")) throw InputError("--steps and --time exclude each other; give one");
    o.end_steps = integer_option(args, "steps", 0);
    if (args.count("steps") && o.end_steps < 1)
        throw InputError("--steps must be at least 1, got " + std::to_string(o.end_steps));
    o.threads = threads_option(args);
    o.quiet = flag_option(args, "quiet");
    o.checkpoint_every = integer_option(args, "checkpoint-every", 0);
    if (args.count("checkpoint-every") && o.checkpoint_every < 1)
        throw InputError("--checkpoint-every must be at least 1, got " + std::to_string(o.checkpoint_every));
    o.checkpoints = flag_option(args, "checkpoint") || o.checkpoint_every > 0;
    if (args.count("resume")) o.resume_path = args["resume"].as<std::string>();
    o.requested_backend = args["backend"].as<std::string>();
    o.has_scene = args.count("scene") > 0;
    o.has_time = args.count("time") > 0;
    o.has_out = args.count("out") > 0;
    if (o.has_out) o.out = args["out"].as<std::string>();
    return o;
}

// One `run`: set-up, the step loop with its frames, guards and checkpoints, and the outputs.
class Run {
   public:
    explicit Run(RunOptions options) : o_(std::move(options)) {}
    int execute();

   private:
    void resolve();                // the scene, the end, the backend and the output directory
    bool build();                  // the setup and the simulation; false when interrupted
    void open_outputs();           // frames, stats, the summary's fixed part
    void print_start();
    void write_frame();
    void count_fluid_inside_objects();  // at each frame, moving 2D objects only
    void write_checkpoint_now();
    void check_guards(const StepReport& r, Progress& progress);
    void step_loop();
    bool record_end();             // stats.csv and summary.json, whatever happened
    int print_end();

    RunOptions o_;
    std::unique_ptr<Checkpoint> resume_;
    Scene scene_;
    double end_time_ = 0;
    std::string backend_, checkpoint_dir_, out_dir_, stats_path_, summary_path_, checkpoint_path_;
    long carved_fluid_ = 0;
    SimulationSetup setup_;
    SpeedLimit runaway_;
    std::string emitter_warning_;
    std::unique_ptr<Simulation> sim_;
    bool continues_directory_ = false;
    int frame_index_ = 0;
    std::vector<double> frame_times_;  // of every frame up to now, for the next checkpoint
    std::unique_ptr<FrameWriter> frames_;
    std::unique_ptr<StatsTable> stats_;
    RunSummary summary_;
    std::unique_ptr<FluidSurfacer> surfacer_;
    std::vector<double> surface_ms_, surface_field_ms_;  // per mesh: all of it, and the colour field's part
    TriangleMesh last_surface_;                          // the frame's surface, for its preview
    std::vector<double> preview_ms_;                     // per preview: drawing, encoding and writing
    std::string last_preview_;                           // the last preview's path
    HostParticles host_;
    double frame_dt_ = 0, next_frame_time_ = 0;
    long checkpoint_step_ = -1;
    std::chrono::steady_clock::time_point wall_start_;
    DiskSyncTotals synced_at_start_;
    std::exception_ptr failure_;
    bool interrupted_ = false;
};

void Run::resolve() {
    // A resumed run takes everything the simulation is built from out of its checkpoint: the
    // scene as the first run resolved it (overrides applied, mesh paths absolute), so that the
    // setup is built exactly as it was.
    if (!o_.resume_path.empty()) {
        if (o_.has_scene || !o_.overrides.empty())
            throw InputError("--resume continues the checkpoint's own scene: give no SCENE and no --set");
        resume_ = std::make_unique<Checkpoint>(read_checkpoint(o_.resume_path));
    }
    scene_ = resume_ ? resolve_scene(resume_->scene, "checkpoint " + o_.resume_path)
                     : scene_from_options(o_.args, o_.overrides);
    end_time_ = number_option(o_.args, "time", scene_.end_time);
    // The same bound as run.end_time: 1e300 s would run for ever.
    if (o_.has_time && !(end_time_ > 0 && end_time_ <= 1e6))
        throw InputError("--time must be in (0, 1e6] seconds, got " + format_number(end_time_));
    if (resume_ && o_.end_steps == 0 && !(resume_->time < end_time_ * (1 - 1e-9)))
        throw InputError("the checkpoint is at t = " + format_number(resume_->time) + " s, already at the end time " +
                         format_number(end_time_) + " s; give a later --time, or --steps");
    // A resumed run left on auto continues on the backend that wrote the checkpoint, where that
    // backend is usable here: the backends round differently, and only the same backend continues
    // bitwise (docs/checkpoints.md). A checkpoint naming neither backend leaves auto as it is.
    const bool saved_backend_usable =
        resume_ && (resume_->backend == "openmp" || (resume_->backend == "cuda" && cuda_backend_info().available));
    backend_ = choose_backend(o_.requested_backend == "auto" && saved_backend_usable ? resume_->backend
                                                                                     : o_.requested_backend);
    if (o_.threads > 0 && backend_ != "openmp" && !o_.quiet)
        std::fprintf(stderr, "meltwater: note: --threads applies to the openmp backend only\n");
    if (resume_) {
        checkpoint_dir_ = std::filesystem::path(o_.resume_path).parent_path().string();
        if (checkpoint_dir_.empty()) checkpoint_dir_ = ".";
    }
    out_dir_ = o_.has_out ? o_.out : resume_ ? checkpoint_dir_ : "results/" + (scene_.name.empty() ? "run" : scene_.name);
    if (out_dir_.empty()) throw InputError("--out: empty directory name");
    stats_path_ = out_dir_ + "/stats.csv";
    summary_path_ = out_dir_ + "/summary.json";
    checkpoint_path_ = out_dir_ + "/" + kCheckpointFileName;
}

bool Run::build() {
    check_host_memory(scene_, backend_, backend_ == "openmp");
    // --threads bounds the set-up too: objects are sampled on the host's OpenMP threads.
    if (backend_ == "openmp") set_host_threads(o_.threads);
    setup_ = build_setup(scene_, &carved_fluid_);
    if (g_interrupted) return false;
    runaway_ = speed_limit(scene_, setup_);
    emitter_warning_ = emitter_overlap_warning(setup_);
    // Before the simulation is built, so that an unwritable --out fails at once; the directories
    // made here are removed again (if still empty) when the run ends before its first step.
    const std::vector<std::string> created = make_directories(out_dir_);
    try {
        // stats.csv and summary.json are renamed into place at the end: a directory by those
        // names would only fail then, after the whole run. A file named frames would fail when the
        // frame writer makes its directory, after the simulation (a GPU upload) is built.
        for (const std::string& path : {stats_path_, summary_path_})
            if (std::filesystem::is_directory(path))
                throw InputError(path + " is a directory; the run writes a file there");
        const std::string frames_path = out_dir_ + "/frames";
        if (scene_.writes_frames() && std::filesystem::exists(frames_path) && !std::filesystem::is_directory(frames_path))
            throw InputError(frames_path + " is a file; the run writes its frames in a directory there");
        sim_ = create_simulation(setup_, backend_, o_.threads);
        if (resume_) sim_->load_state(resume_->state);
    } catch (...) {
        remove_created_directories(created);
        throw;
    }
    if (g_interrupted) {
        remove_created_directories(created);
        return false;
    }
    return true;
}

void Run::open_outputs() {
    // Resumed in its checkpoint's directory, the run continues that directory's frames and
    // stats.csv from the checkpoint on (what the first run wrote after it goes); elsewhere it
    // starts them afresh, its frames numbered on from the checkpoint's.
    continues_directory_ = resume_ && same_directory(out_dir_, checkpoint_dir_);
    frame_index_ = resume_ ? static_cast<int>(resume_->frame_times.size()) : 0;
    const RemovedOutputs removed = remove_earlier_outputs(out_dir_, continues_directory_ ? frame_index_ : 0,
                                                          continues_directory_);
    if (!o_.quiet && !continues_directory_ && (removed.frames > 0 || !removed.records.empty())) {
        std::string what = removed.frames > 0 ? count_of(removed.frames, "frame") : "";
        for (const std::string& name : removed.records) what += (what.empty() ? "" : ", ") + name;
        std::fprintf(stderr, "meltwater: note: removed an earlier run's outputs from %s (%s)\n", out_dir_.c_str(),
                     what.c_str());
    }
    if (resume_) frame_times_ = resume_->frame_times;
    if (scene_.writes_frames()) {
        frames_ = std::make_unique<FrameWriter>(out_dir_ + "/frames", scene_.frame_formats());
        frames_->set_objects(setup_.solids);
        if (continues_directory_) frames_->keep_earlier(frame_times_);
    }
    stats_ = std::make_unique<StatsTable>(sim_->stage_names(), sim_->last_report().column_names);
    std::string stats_warning;
    if (continues_directory_) {
        const EarlierStatsRows earlier = stats_rows_up_to(stats_path_, stats_->header(), resume_->step);
        stats_->keep_earlier_rows(earlier.rows);
        if (!earlier.problem.empty())
            stats_warning = earlier.problem + ": the resumed run's stats.csv starts after the checkpoint, at step " +
                            std::to_string(resume_->step + 1);
    }
    summary_.backend = sim_->backend_name();
    summary_.device = sim_->device_name();
    summary_.threads = o_.threads;
    summary_.particles = sim_->counts();
    summary_.fluid_carved = carved_fluid_;
    summary_.device_bytes = sim_->device_bytes();
    summary_.speed_limit = runaway_.limit;
    char stop[64];
    if (o_.end_steps > 0) std::snprintf(stop, sizeof stop, "steps %ld", o_.end_steps);
    else std::snprintf(stop, sizeof stop, "time %g s", end_time_);
    summary_.stop_condition = stop;
    if (resume_) {
        summary_.resumed_from = o_.resume_path;
        summary_.resumed_step = resume_->step;
        summary_.resumed_time = resume_->time;
        summary_.simulated_time = resume_->time;
    }
    const std::string heat_warning = heat_substeps_warning(sim_->heat_substeps_needed(double(scene_.params.solver.dt)),
                                                           scene_.params.heat.max_substeps);
    for (const std::string& warning : {scene_.kernel_warning(), heat_warning, emitter_warning_, stats_warning}) {
        if (warning.empty()) continue;
        std::fprintf(stderr, "meltwater: warning: %s\n", warning.c_str());
        summary_.warnings.push_back(warning);
    }
    surfacer_ = std::make_unique<FluidSurfacer>(scene_.params, scene_.surface_voxel, o_.threads);
    frame_dt_ = 1.0 / scene_.fps;
    next_frame_time_ = resume_ ? resume_->next_frame_time : frame_dt_;
}

void Run::print_start() {
    if (o_.quiet) return;
    const ParticleCounts& c = summary_.particles;
    // Carving changes how much fluid a scene holds: say so where the counts are given.
    const std::string carved =
        carved_fluid_ > 0 ? "; " + with_thousands(carved_fluid_) + " fluid carved out where solids stand" : "";
    const std::string pending =
        c.by_type[kPending] > 0 ? ", " + with_thousands(c.by_type[kPending]) + " to be emitted" : "";
    std::fprintf(stderr, "meltwater: %s (%s): %s particles (%s fluid%s, %s boundary%s) on %s [%s], %s; output in %s\n",
                 scene_.name.empty() ? "scene" : scene_.name.c_str(), scene_.source.c_str(),
                 with_thousands(c.total()).c_str(), with_thousands(c.by_type[kFluid]).c_str(), pending.c_str(),
                 with_thousands(c.total() - c.by_type[kFluid] - c.by_type[kPending]).c_str(), carved.c_str(),
                 summary_.backend.c_str(), summary_.device.c_str(), summary_.stop_condition.c_str(), out_dir_.c_str());
    if (resume_)
        std::fprintf(stderr, "meltwater: resuming from %s: step %ld, t = %.6g s (written on %s)\n",
                     o_.resume_path.c_str(), resume_->step, resume_->time, resume_->backend.c_str());
}

void Run::write_frame() {
    if (!frames_) return;
    sim_->download(host_);
    frames_->write(frame_index_, host_, sim_->time());
    count_fluid_inside_objects();
    const FrameFormats& formats = frames_->formats();
    if (formats.surface) {
        FluidSurfacer::Surface surface = surfacer_->build(*sim_, host_);
        frames_->write_surface(frame_index_, surface.mesh);
        surface_ms_.push_back(surface.ms);
        surface_field_ms_.push_back(surface.field_ms);
        summary_.surfaces = static_cast<int>(surface_ms_.size());
        summary_.surface_ms_median = median_of(surface_ms_);
        summary_.surface_field_ms_median = median_of(surface_field_ms_);
        summary_.surface_triangles_last = static_cast<long>(surface.mesh.triangles.size());
        if (formats.preview) last_surface_ = std::move(surface.mesh);
    }
    if (formats.vdb) {
        // The surface's field when it was just computed, else this frame's own.
        const FluidSurfacer::Field& field = formats.surface ? surfacer_->last_field() : surfacer_->field(*sim_, host_);
        frames_->write_fluid_grids(frame_index_, field);
    }
    if (formats.preview) {
        const auto start = std::chrono::steady_clock::now();
        std::vector<PreviewMesh> meshes = object_preview_meshes(setup_.solids, host_, scene_.params.dimensions);
        if (formats.surface) meshes.push_back(surface_preview_mesh(last_surface_, kContourWidthInR0 * double(scene_.params.fluid.spacing)));
        last_preview_ = frames_->write_preview(
            frame_index_, preview_picture(scene_, host_, std::move(meshes), sim_->time(), frame_index_, runaway_.scale()));
        preview_ms_.push_back(seconds_since(start) * 1000);
        summary_.previews = static_cast<int>(preview_ms_.size());
        summary_.preview_ms_median = median_of(preview_ms_);
    }
    frame_times_.push_back(sim_->time());
    ++frame_index_;
}

void Run::count_fluid_inside_objects() {
    if (!std::any_of(setup_.solids.begin(), setup_.solids.end(), has_moving_outline)) return;
    long inside = 0;
    for (long count : fluid_inside_outlines(setup_.solids, host_)) inside += std::max(0L, count);
    ++summary_.inside_frames;
    summary_.fluid_inside_max = std::max(summary_.fluid_inside_max, inside);
    summary_.fluid_inside_sum += double(inside);
    summary_.fluid_inside_last = inside;
}

// The checkpoint: the state now, with the scene and the frame clock (checkpoint_file.hpp).
// stats.csv goes to disk first: a run killed at any moment then leaves a stats.csv that reaches
// at least its last checkpoint's step, which a resume continues from.
void Run::write_checkpoint_now() {
    stats_->write(stats_path_);
    Checkpoint c;
    c.scene = scene_.resolved;
    c.backend = summary_.backend;
    c.step = sim_->last_report().step;
    c.time = sim_->time();
    c.frame_times = frame_times_;
    c.next_frame_time = next_frame_time_;
    sim_->save_state(c.state);
    write_checkpoint(checkpoint_path_, c);
    checkpoint_step_ = c.step;
    summary_.checkpoint = checkpoint_path_;
    summary_.checkpoint_step = c.step;
}

// The run stops at the step that passes a guard (docs/running.md).
void Run::check_guards(const StepReport& r, Progress& progress) {
    // Against the fluid there is now: melting objects add to it (the counts are host figures).
    try {
        check_run_guards(r, sim_->counts().by_type[kFluid], *stats_, scene_, runaway_);
    } catch (...) {
        progress.finish();
        throw;
    }
}

void Run::step_loop() {
    auto last_stats_write = wall_start_;
    double stats_write_seconds = 0;  // how long the last rewrite of stats.csv took
    if (!resume_) write_frame();     // frame 0: the initial state (a resumed run has its frames)
    Progress progress(o_.quiet ? Progress::Mode::kQuiet : Progress::Mode::kAuto, o_.end_steps, end_time_,
                      resume_ ? resume_->step : 0, resume_ ? resume_->time : 0.0);
    long steps_done = 0;
    // Stop at the step that reaches end_time (to a relative tolerance, so 0.1 + 0.1 + ... counts).
    while (o_.end_steps > 0 ? steps_done < o_.end_steps : sim_->time() < end_time_ * (1 - 1e-9)) {
        if (g_interrupted) {
            interrupted_ = true;
            break;
        }
        try {
            sim_->step();
        } catch (const DeviceError& e) {
            // A step can still allocate (neighbour lists growing as the flow compresses): say where
            // the run stood and what it held.
            progress.finish();
            throw DeviceError(device_error_in_step(e.what(), steps_done + 1, long(summary_.particles.total()),
                                                   summary_.device_bytes));
        } catch (...) {
            progress.finish();
            throw;
        }
        ++steps_done;
        const StepReport& r = sim_->last_report();
        stats_->add(r);
        summary_.steps = steps_done;
        summary_.simulated_time = r.time;
        summary_.lost_particles = r.lost_particles;
        progress.update(r);
        check_guards(r, progress);
        if (r.time >= next_frame_time_ * (1 - 1e-9)) {
            write_frame();
            // The next frame time after now (a step longer than 1/fps skips frame times).
            next_frame_time_ = (std::floor(r.time / frame_dt_ * (1 + 1e-9)) + 1) * frame_dt_;
        }
        if (o_.checkpoint_every > 0 && r.step % o_.checkpoint_every == 0) write_checkpoint_now();
        // Keep stats.csv current for a run that dies: every 5 s, or less often once the file is so
        // long that rewriting it would take more than 5% of the run.
        if (seconds_since(last_stats_write) > std::max(5.0, 20 * stats_write_seconds)) {
            const auto write_start = std::chrono::steady_clock::now();
            stats_->write(stats_path_);
            stats_write_seconds = seconds_since(write_start);
            last_stats_write = std::chrono::steady_clock::now();
        }
    }
    progress.finish();
}

bool Run::record_end() {
    // A run that ended or was stopped leaves its checkpoint (one that failed does not: its state
    // is what failed).
    if (!failure_ && o_.checkpoints && checkpoint_step_ != sim_->last_report().step) {
        try {
            write_checkpoint_now();
        } catch (...) {
            failure_ = std::current_exception();
        }
    }
    summary_.wall_seconds = seconds_since(wall_start_);
    const DiskSyncTotals synced = disk_sync_totals();
    summary_.synced_files = synced.files - synced_at_start_.files;
    summary_.sync_seconds = synced.seconds - synced_at_start_.seconds;
    summary_.frames = frames_ ? frames_->written() : 0;
    // The counts by type now (an emitter's released fluid is fluid, a melted solid's too): one
    // host copy at the end.
    try {
        sim_->download(host_);
        ParticleCounts at_end;
        for (std::uint8_t type : host_.type)
            if (type < kParticleTypeCount) ++at_end.by_type[type];
        summary_.particles_at_end = at_end;
    } catch (const std::exception&) {
        summary_.particles_at_end.reset();  // a device that failed: not known
    }
    if (failure_) {
        summary_.status = "failed";
        try {
            std::rethrow_exception(failure_);
        } catch (const std::exception& e) {
            summary_.error = e.what();
        }
    } else if (interrupted_) {
        summary_.status = "interrupted";
    }
    // Whatever happened, leave whole stats.csv and summary.json behind.
    try {
        stats_->write(stats_path_);
        write_summary(summary_path_, summary_, *stats_, scene_);
    } catch (const std::exception& e) {
        if (!failure_) throw;
        std::fprintf(stderr, "meltwater: error: could not record the failure: %s\n", e.what());
        return false;
    }
    return true;
}

int Run::print_end() {
    const StatsTable& stats = *stats_;
    if (stats.retried_steps() > 0 && !o_.quiet)
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
                     count_of(stats.unconverged_steps(), "step").c_str(), scene_.params.solver.max_iterations,
                     scene_.params.solver.dt_mode == TimeStepMode::kCfl
                         ? "; halving the step (up to six times) did not rescue them: raise solver.max_iterations, or "
                           "loosen solver.eta or solver.eta_max"
                         : "; use a smaller dt, more iterations, or dt_mode \"cfl\"");
    if (summary_.lost_particles > 0)
        std::fprintf(stderr, "meltwater: warning: %s left the domain (column lost_particles of stats.csv)\n",
                     count_of(summary_.lost_particles, "fluid particle").c_str());
    std::error_code ec;
    const std::string shown = std::filesystem::absolute(out_dir_, ec).lexically_normal().string();
    // The fluid's figures mean nothing in a scene without fluid (all zero): say so instead.
    char fluid_figures[160] = "no fluid";
    if (summary_.particles.by_type[kFluid] > 0 || stats.has_column("melted") || stats.has_column("emitted"))
        std::snprintf(fluid_figures, sizeof fluid_figures, "density error avg %.3g%% max %.3g%%, %.1f iterations/step",
                      100 * stats.density_error_avg(), 100 * stats.density_error_max(), stats.iterations_avg());
    std::printf("meltwater: %s %s to t=%.4g s in %.1f s (%.1f ms/step median, %s)\n",
                interrupted_ ? "interrupted after" : "ran", count_of(summary_.steps, "step").c_str(),
                summary_.simulated_time, summary_.wall_seconds, stats.median_total_ms(), fluid_figures);
    const std::string surfaces = summary_.surfaces > 0 ? " and " + count_of(summary_.surfaces, "surface") + " (" +
                                                             format_number(summary_.surface_ms_median) + " ms each)"
                                                       : "";
    std::printf("meltwater: results in %s (%s%s in frames/, stats.csv, summary.json%s)\n",
                ec ? out_dir_.c_str() : shown.c_str(), count_of(summary_.frames, "frame").c_str(), surfaces.c_str(),
                summary_.checkpoint.empty() ? "" : ", checkpoint.mwc");
    // Where a person can look first: the last picture, or how to draw one.
    if (!last_preview_.empty()) {
        const std::string picture = std::filesystem::absolute(last_preview_, ec).lexically_normal().string();
        std::printf("meltwater: picture of the last frame: %s\n", ec ? last_preview_.c_str() : picture.c_str());
    }
    if (!summary_.checkpoint.empty() && !o_.quiet)
        std::fprintf(stderr, "meltwater: checkpoint at step %ld (t = %.6g s); continue with: meltwater run --resume %s "
                     "--time T\n", summary_.checkpoint_step, summary_.simulated_time, summary_.checkpoint.c_str());
    std::fflush(stdout);
    return interrupted_ ? 130 : 0;
}

int Run::execute() {
    const StopSignals stop_signals;
    resolve();
    if (!build()) return report_interrupted_setup();
    open_outputs();
    print_start();
    wall_start_ = std::chrono::steady_clock::now();
    synced_at_start_ = disk_sync_totals();
    try {
        step_loop();
    } catch (...) {
        failure_ = std::current_exception();
    }
    const bool recorded = record_end();
    if (failure_) {
        std::fprintf(stderr, "meltwater: stopped after %s at t=%.4g s; %s%s kept in %s\n",
                     count_of(summary_.steps, "step").c_str(), summary_.simulated_time,
                     count_of(summary_.frames, "frame").c_str(), recorded ? ", stats.csv and summary.json" : "",
                     out_dir_.c_str());
        std::rethrow_exception(failure_);
    }
    return print_end();
}

}  // namespace

int command_run(int argc, char** argv) {
    cxxopts::Options options = run_options();
    RunOptions o = read_run_options(options, argc, argv);
    if (flag_option(o.args, "help")) {
        std::printf("%s\n", options.help().c_str());
        return 0;
    }
    return Run(std::move(o)).execute();
}

}  // namespace mw
