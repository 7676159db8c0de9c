#include "python/simulation_handle.hpp"

#include <filesystem>

#include <omp.h>

#include "apps/cli_common.hpp"
#include "apps/scene_builder.hpp"
#include "common/errors.hpp"
#include "apps/run_guards.hpp"
#include "simulation/factory.hpp"

namespace mw::python {

namespace {
// The most OpenMP threads, as the CLI's --threads allows: each reserves a stack, and libgomp
// ends the process when it cannot create them.
constexpr int kMaxThreads = 1024;

// What threads = 0 means: OpenMP's own count (all cores, or OMP_NUM_THREADS) as it was before the
// first simulation. set_host_threads changes OpenMP's count for the whole process, so that after
// a simulation with threads = 1 "the default" would otherwise stay 1 for every later one.
int all_cores() {
    static const int count = omp_get_max_threads();
    return count;
}
}  // namespace

SimulationHandle::SimulationHandle(SceneHandle scene, const std::string& backend, int threads, bool guards)
    : scene_(std::move(scene)), guards_(guards) {
    const int cores = all_cores();  // before anything here sets OpenMP's count
    if (threads < 0 || threads > kMaxThreads)
        throw InputError("threads must be in [1, " + std::to_string(kMaxThreads) + "] (0: all cores), got " +
                         std::to_string(threads));
    threads_ = threads > 0 ? threads : cores;
    const Scene& s = scene_.scene;
    backend_ = choose_backend(backend);
    check_host_memory(s, backend_, backend_ == "openmp");
    // The threads bound the set-up too: objects are sampled on the host's OpenMP threads.
    if (backend_ == "openmp") set_host_threads(threads_);
    const SimulationSetup setup = build_setup(s, &carved_fluid_);
    runaway_ = mw::speed_limit(s, setup);
    sim_ = create_simulation(setup, backend_, threads_);
    solids_ = setup.solids;  // their meshes go with every frame
    stats_ = std::make_unique<StatsTable>(sim_->stage_names(), sim_->last_report().column_names);
    const std::string heat_warning =
        heat_substeps_warning(sim_->heat_substeps_needed(double(s.params.solver.dt)), s.params.heat.max_substeps);
    for (const std::string& w : {s.kernel_warning(), heat_warning, emitter_overlap_warning(setup)})
        if (!w.empty()) warnings_.push_back(w);
}

const StepReport& SimulationHandle::step() {
    snapshot_.reset();
    try {
        sim_->step();
    } catch (const DeviceError& e) {
        // A step can still allocate (neighbour lists growing as the flow compresses).
        throw DeviceError(device_error_in_step(e.what(), sim_->last_report().step + 1, sim_->counts().total(),
                                               sim_->device_bytes()));
    }
    const StepReport& r = sim_->last_report();
    stats_->add(r);
    if (guards_) check_run_guards(r, sim_->counts().by_type[kFluid], *stats_, scene_.scene, runaway_);
    return r;
}

Snapshot SimulationHandle::particles() {
    if (!snapshot_) {
        auto fresh = std::make_shared<HostParticles>();
        sim_->download(*fresh);
        snapshot_ = std::move(fresh);
    }
    return snapshot_;
}

FrameSeries& SimulationHandle::frames(const std::string& directory) {
    if (directory.empty()) throw InputError("frames: empty directory name");
    // One series per directory however it is spelt ("out", "./out/").
    std::error_code error;
    std::filesystem::path normal = std::filesystem::absolute(directory, error).lexically_normal();
    if (!normal.has_filename()) normal = normal.parent_path();
    const std::string key = error ? directory : normal.string();
    auto found = frames_.find(key);
    if (found == frames_.end())
        found = frames_.emplace(key, FrameSeries(directory, scene_.scene.frame_formats(), solids_)).first;
    return found->second;
}

std::string SimulationHandle::write_frame(FrameSeries& series) {
    const std::string path = series.write(*particles(), sim_->time());
    series.frame_written_at(sim_->time(), scene_.scene.fps);
    return path;
}

}  // namespace mw::python
