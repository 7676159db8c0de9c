// What `meltwater info` says a run of a scene will cost before it runs: the disk its frames take
// (from the particle counts and output.formats) and the time its steps take (a few steps timed on
// the backend that would run them, scaled to the run's step count).
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "apps/scene.hpp"
#include "simulation/simulation.hpp"

namespace mw {

struct DiskEstimate {
    long frames = 0;
    // Bytes of each kind of file over the whole run (the static boundary's, once), by name.
    std::vector<std::pair<std::string, double>> parts;
    double total = 0;
    // Whether a part depends on the fluid's surface, estimated from the fluid's start.
    bool surface_estimated = false;
};
// `counts`: the setup's. Particle frames are sized with every emitter's particles released (their
// largest); surfaces and grids from the starting fluid's blocks, which splashing enlarges.
DiskEstimate estimate_disk(const Scene& scene, const ParticleCounts& counts, const SimulationSetup& setup);

struct TimeEstimate {
    int steps_timed = 0;
    double ms_per_step = 0;
    double steps_to_end = 0;   // fixed dt: exact; CFL: at the largest step dt, so a least count
    double seconds = 0;        // steps_to_end × ms_per_step
    bool lower_bound = false;  // CFL mode: the steps shorten as the fluid speeds up
};
// Times `steps` steps of `sim` (which they advance) for a run of `scene` to `end_time`.
TimeEstimate time_steps(Simulation& sim, const Scene& scene, double end_time, int steps);

}  // namespace mw
