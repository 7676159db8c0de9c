#include "apps/fluid_inside_objects.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "algorithms/particle_types.hpp"

namespace mw {

bool has_moving_outline(const SolidSetup& solid) {
    if (solid.kind != SolidKind::kRigid && solid.kind != SolidKind::kElastic) return false;
    return !solid.triangles.empty() && std::all_of(solid.triangles.begin(), solid.triangles.end(), [](const std::array<int, 3>& t) {
               return t[2] == t[0] && t[1] != t[0];
           });
}

namespace {

// `solid`'s outer loops, each its edges: those that run counter-clockwise, as the sampler
// oriented them (solid on the left), so that a hole (clockwise) is left out and its cavity counts
// inside; an island within a hole is an outer loop of its own.
std::vector<std::vector<std::array<int, 2>>> outer_loops(const SolidSetup& solid, const HostParticles& p) {
    std::map<int, int> next;
    for (const std::array<int, 3>& t : solid.triangles) next[t[0]] = t[1];
    std::vector<std::vector<std::array<int, 2>>> outer;
    std::set<int> seen;
    for (const auto& [first, unused] : next) {
        if (seen.count(first)) continue;
        std::vector<std::array<int, 2>> loop;
        double twice_area = 0;
        for (int a = first; !seen.count(a) && next.count(a); a = next[a]) {
            seen.insert(a);
            const int b = next[a];
            const Vec3 xa = p.position[solid.gp[std::size_t(a)]], xb = p.position[solid.gp[std::size_t(b)]];
            twice_area += double(xa.x) * double(xb.y) - double(xb.x) * double(xa.y);
            loop.push_back({a, b});
        }
        if (twice_area > 0) outer.push_back(std::move(loop));
    }
    return outer;
}

}  // namespace

std::vector<long> fluid_inside_outlines(const std::vector<SolidSetup>& solids, const HostParticles& p) {
    std::vector<long> inside(solids.size(), -1);
    for (std::size_t s = 0; s < solids.size(); ++s) {
        const SolidSetup& solid = solids[s];
        if (!has_moving_outline(solid)) continue;
        const auto at = [&](int g) { return p.position[solid.gp[std::size_t(g)]]; };
        const std::vector<std::vector<std::array<int, 2>>> loops = outer_loops(solid, p);
        // Inside one outer loop by the even-odd rule (a loop of its own: none nests in another).
        const auto inside_loop = [&](const std::vector<std::array<int, 2>>& loop, Vec3 x) {
            bool in = false;
            for (const std::array<int, 2>& e : loop) {
                const Vec3 a = at(e[0]), b = at(e[1]);
                if ((a.y > x.y) != (b.y > x.y) && x.x < a.x + (x.y - a.y) * (b.x - a.x) / (b.y - a.y)) in = !in;
            }
            return in;
        };
        Real lo_x = at(0).x, hi_x = lo_x, lo_y = at(0).y, hi_y = lo_y;
        for (std::size_t g = 0; g < solid.gp.size(); ++g) {
            const Vec3 x = at(int(g));
            lo_x = std::min(lo_x, x.x), hi_x = std::max(hi_x, x.x);
            lo_y = std::min(lo_y, x.y), hi_y = std::max(hi_y, x.y);
        }
        long count = 0;
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            const Vec3 x = p.position[i];
            if (p.type[i] != kFluid || x.x < lo_x || x.x > hi_x || x.y < lo_y || x.y > hi_y) continue;
            count += std::any_of(loops.begin(), loops.end(), [&](const auto& loop) { return inside_loop(loop, x); });
        }
        inside[s] = count;
    }
    return inside;
}

}  // namespace mw
