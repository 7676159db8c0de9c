#include "apps/fluid_inside_objects.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "algorithms/particle_types.hpp"
#include "sampling/outline.hpp"

namespace mw {

bool has_moving_outline(const SolidSetup& solid) {
    return (solid.kind == SolidKind::kRigid || solid.kind == SolidKind::kElastic) && is_outline(solid.triangles);
}

namespace {

// `solid`'s outer loops, each its edges: those that run counter-clockwise, as the sampler
// oriented them (solid on the left), so that a hole (clockwise) is left out and its cavity counts
// inside; an island within a hole is an outer loop of its own. `gp_at`: the GPs where they stand.
std::vector<std::vector<std::array<int, 2>>> outer_loops(const SolidSetup& solid, const std::vector<Vec3d>& gp_at) {
    std::map<int, int> next;
    for (const std::array<int, 3>& t : solid.triangles) next[t[0]] = t[1];
    std::vector<std::vector<std::array<int, 2>>> outer;
    std::set<int> seen;
    for (const auto& [first, unused] : next) {
        if (seen.count(first)) continue;
        std::vector<std::array<int, 2>> loop;
        for (int a = first; !seen.count(a) && next.count(a); a = next[a]) {
            seen.insert(a);
            loop.push_back({a, next[a]});
        }
        if (twice_signed_area(gp_at, loop) > 0) outer.push_back(std::move(loop));
    }
    return outer;
}

}  // namespace

std::vector<long> fluid_inside_outlines(const std::vector<SolidSetup>& solids, const HostParticles& p) {
    std::vector<long> inside(solids.size(), -1);
    for (std::size_t s = 0; s < solids.size(); ++s) {
        const SolidSetup& solid = solids[s];
        if (!has_moving_outline(solid)) continue;
        std::vector<Vec3d> gp_at(solid.gp.size());
        double lo_x = HUGE_VAL, hi_x = -HUGE_VAL, lo_y = HUGE_VAL, hi_y = -HUGE_VAL;
        for (std::size_t g = 0; g < solid.gp.size(); ++g) {
            const Vec3 x = p.position[solid.gp[g]];
            gp_at[g] = Vec3d(double(x.x), double(x.y), 0.0);
            lo_x = std::min(lo_x, gp_at[g].x()), hi_x = std::max(hi_x, gp_at[g].x());
            lo_y = std::min(lo_y, gp_at[g].y()), hi_y = std::max(hi_y, gp_at[g].y());
        }
        // Inside any outer loop by the even-odd rule (a loop of its own: none nests in another).
        const std::vector<std::vector<std::array<int, 2>>> loops = outer_loops(solid, gp_at);
        long count = 0;
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            const double x = double(p.position[i].x), y = double(p.position[i].y);
            if (p.type[i] != kFluid || x < lo_x || x > hi_x || y < lo_y || y > hi_y) continue;
            count += std::any_of(loops.begin(), loops.end(), [&](const auto& loop) { return inside_loops(gp_at, loop, x, y); });
        }
        inside[s] = count;
    }
    return inside;
}

}  // namespace mw
