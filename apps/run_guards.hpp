// The guards of `meltwater run` (docs/running.md): the step that ends with more than
// boundary.max_lost_fraction of the fluid gone, a peak density error above
// solver.max_density_error, or a particle faster than solver.max_speed stops the run with
// SimulationError naming the step, the limit and what PCISPH did before it. The program and the
// Python module (python/) both stop their runs here.
#pragma once
#include <string>

#include "apps/run_outputs.hpp"
#include "apps/scene.hpp"
#include "apps/speed_limit.hpp"
#include "simulation/simulation.hpp"

namespace mw {

// Throws SimulationError when report `r` passes a guard; `fluid_now` is the fluid there is now
// (melting adds to it), `stats` the run's steps so far, `r` included.
void check_run_guards(const StepReport& r, long fluid_now, const StatsTable& stats, const Scene& scene,
                      const SpeedLimit& limit);

// A DeviceError from inside a step, with where the run stood, as the CLI says it: `what` and
// "(in step N; the P particles held B before it)".
std::string device_error_in_step(const std::string& what, long step, long particles, std::size_t device_bytes);

}  // namespace mw
