#include "apps/run_guards.hpp"

#include <algorithm>
#include <cstdio>

#include "apps/cli_common.hpp"
#include "common/errors.hpp"

namespace mw {

namespace {
// What PCISPH did before the run stopped (the steps it diverged in or ran out of iterations), or "".
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

std::string or_blew_up(const std::string& hint) {
    return !hint.empty() ? hint : std::string("; the run blew up (see the last frames and stats.csv)");
}

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
    return head + ("solver.max_density_error " + format_number(scene.max_density_error)) +
           or_blew_up(failed_iterations_hint(stats));
}

std::string runaway_message(const StepReport& r, const SpeedLimit& limit, const StatsTable& stats) {
    const bool solid = r.solid_max_speed > r.max_speed;
    char head[200];
    std::snprintf(head, sizeof head, "step %ld (t = %.6g s, dt = %.3g s): %s moves at %.4g m/s, more than ", r.step,
                  r.time, r.dt, solid ? "a solid's particle" : "a fluid particle",
                  solid ? r.solid_max_speed : r.max_speed);
    return head + describe(limit) + or_blew_up(failed_iterations_hint(stats));
}
}  // namespace

void check_run_guards(const StepReport& r, long fluid_now, const StatsTable& stats, const Scene& scene,
                      const SpeedLimit& limit) {
    if (r.lost_particles > scene.max_lost_fraction * double(fluid_now))
        throw SimulationError(lost_fluid_message(r, fluid_now, stats, scene));
    if (r.density_error_max > scene.max_density_error) throw SimulationError(density_blowup_message(r, stats, scene));
    if (limit.limit > 0 && std::max(r.max_speed, r.solid_max_speed) > limit.limit)
        throw SimulationError(runaway_message(r, limit, stats));
}

std::string device_error_in_step(const std::string& what, long step, long particles, std::size_t device_bytes) {
    return what + " (in step " + std::to_string(step) + "; the " + with_thousands(particles) + " particles held " +
           format_bytes(double(device_bytes)) + " before it)";
}

}  // namespace mw
