// One simulation for the Python module, built as `meltwater run` builds it: the backend chosen
// and checked, the host memory checked, the scene's particles (objects sampled on the host's
// threads), the guards' speed limit, the scene's warnings, the simulation on its backend. It
// steps, records each step (stats.csv) and applies the run's guards after it; it downloads the
// particles at most once per state. Nothing here touches Python: the binding calls it with the
// interpreter's lock released.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "apps/run_outputs.hpp"
#include "apps/speed_limit.hpp"
#include "python/frame_series.hpp"
#include "python/particle_arrays.hpp"
#include "python/scene_handle.hpp"
#include "simulation/simulation.hpp"

namespace mw::python {

class SimulationHandle {
   public:
    // `backend`: "auto", "cuda" or "openmp" (choose_backend: DeviceError when CUDA is asked for
    // and unusable); `threads`: the OpenMP threads of the set-up and the openmp backend, 0 for
    // all cores (OpenMP's count when the first simulation was made); `guards`: whether a step
    // that passes one of the run's guards raises SimulationError.
    SimulationHandle(SceneHandle scene, const std::string& backend, int threads, bool guards);

    // One step and its record; SimulationError from the step or a guard, DeviceError with where
    // the run stood.
    const StepReport& step();
    const StepReport& last_report() const { return sim_->last_report(); }

    // The particles now, downloaded once per state.
    Snapshot particles();
    // The series of frames written into `directory` (made the first time it is named).
    FrameSeries& frames(const std::string& directory);
    // Writes the state now as the next frame of `series`; returns its path.
    std::string write_frame(FrameSeries& series);
    // stats.csv of the steps so far, as `meltwater run` writes it.
    void write_stats(const std::string& path) const { stats_->write(path); }

    const SceneHandle& scene() const { return scene_; }
    const Simulation& simulation() const { return *sim_; }
    const std::string& backend() const { return backend_; }
    int threads() const { return threads_; }  // the count used, never 0
    long fluid_carved() const { return carved_fluid_; }
    double speed_limit() const { return runaway_.limit; }
    // The scene's warnings, as `meltwater run` prints them before its first step.
    const std::vector<std::string>& warnings() const { return warnings_; }
    const std::vector<SolidSetup>& solids() const { return solids_; }

   private:
    SceneHandle scene_;
    std::string backend_;
    int threads_ = 0;
    bool guards_ = true;
    long carved_fluid_ = 0;
    SpeedLimit runaway_;
    std::vector<std::string> warnings_;
    std::unique_ptr<Simulation> sim_;
    std::unique_ptr<StatsTable> stats_;
    Snapshot snapshot_;  // null when the state has changed since the last download
    std::map<std::string, FrameSeries> frames_;  // by the directory's absolute path
    std::vector<SolidSetup> solids_;             // the setup's objects, whose meshes go with frames
};

}  // namespace mw::python
