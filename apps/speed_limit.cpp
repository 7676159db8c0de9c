#include "apps/speed_limit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "algorithms/particle_types.hpp"

namespace mw {

SpeedLimit speed_limit(const Scene& scene, const SimulationSetup& setup) {
    SpeedLimit out;
    for (std::size_t i = 0; i < setup.velocity.size(); ++i)
        if (setup.type[i] != kPending) out.start = std::max(out.start, double(norm(setup.velocity[i])));
    for (const EmitterSetup& e : setup.emitters) out.start = std::max(out.start, double(e.speed));
    out.fall = fall_speed(scene);
    out.automatic = !scene.max_speed.has_value();
    out.limit = out.automatic ? kRunawaySpeedFactor * out.scale() : *scene.max_speed;
    return out;
}

double fall_speed(const Scene& scene) {
    const Vec3 g = scene.params.gravity;
    const double g_norm = double(norm(g));
    if (!(g_norm > 0)) return 0;
    // The domain box's extent along gravity's direction.
    const Vec3 extent = scene.params.domain_max - scene.params.domain_min;
    const double along =
        (std::fabs(double(g.x)) * extent.x + std::fabs(double(g.y)) * extent.y + std::fabs(double(g.z)) * extent.z) /
        g_norm;
    return std::sqrt(2 * g_norm * along);
}

std::string describe(const SpeedLimit& limit) {
    char text[300];
    if (limit.automatic)
        std::snprintf(text, sizeof text,
                      "solver.max_speed %.4g m/s (%g times the scene's %.3g m/s: its fastest start %.3g m/s and a "
                      "fall through the domain %.3g m/s)",
                      limit.limit, kRunawaySpeedFactor, limit.scale(), limit.start, limit.fall);
    else
        std::snprintf(text, sizeof text, "solver.max_speed %.4g m/s", limit.limit);
    return text;
}

}  // namespace mw
