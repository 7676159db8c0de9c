// Small solid scenes for the LSM tests: procedural meshes sampled by the real sampler, run through
// the Simulation interface on the OpenMP backend.
#pragma once
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "simulation/simulation.hpp"
#include "apps/scene_builder.hpp"
#include "simulation/factory.hpp"
#include "sampling/procedural_meshes.hpp"

namespace lsm_test {

using namespace mw;

inline SimulationSetup empty_setup(Vec3 lo, Vec3 hi, Real dt, Vec3 gravity, Real r0 = Real(0.02)) {
    SimulationSetup s;
    s.params.domain_min = lo;
    s.params.domain_max = hi;
    s.params.gravity = gravity;
    s.params.fluid.spacing = r0;
    s.params.fluid.support_radius = 2 * r0;
    s.params.solver.dt = dt;
    s.params.boundary.walls = false;  // solids alone: LSM keeps them inside the domain box
    return s;
}

// A solid for the shape matching's own tests: undamped (no region damping unless `damping`, and
// no whole-body damping, whose default is 5/s) unless a test sets it.
inline SolidSetup solid(SolidKind kind, Real density = 1000, int w = 2, Real alpha = 1, Real damping = 0) {
    SolidSetup s;
    s.name = "body";
    s.kind = kind;
    s.density = density;
    s.region_half_width = w;
    s.stiffness = alpha;
    s.damping = damping;
    s.body_damping = 0;
    return s;
}

// A box of size (x, y, z) centred at c (rotated by rot_deg about x, y, z).
inline TriangleMesh box_mesh(Vec3 size, Vec3 c, Vec3 rot_deg = Vec3{0, 0, 0}) {
    TriangleMesh m = make_box(Vec3d(size.x, size.y, size.z));
    MeshTransform t;
    t.rotation_deg = Vec3d(rot_deg.x, rot_deg.y, rot_deg.z);
    t.translation = Vec3d(c.x, c.y, c.z);
    apply_transform(m, t);
    return m;
}

inline void add(SimulationSetup& s, const TriangleMesh& mesh, SolidSetup solid, Vec3 velocity = Vec3{0, 0, 0},
                const std::function<bool(const Vec3&)>& pinned = nullptr) {
    add_solid_object(s, mesh, solid, velocity, static_cast<std::int32_t>(s.solids.size()), s.params.fluid.spacing,
                     s.params.fluid.support_radius, pinned);
}

inline std::unique_ptr<Simulation> make_openmp(const SimulationSetup& s) { return create_openmp_simulation(s, 1); }  // one thread: the suite runs beside other jobs on 2 cores

// IBP indices (scene order) of all moving solids.
inline std::vector<std::uint32_t> ibps(const SimulationSetup& s) {
    std::vector<std::uint32_t> out;
    for (const auto& o : s.solids) out.insert(out.end(), o.ibp.begin(), o.ibp.end());
    return out;
}

struct Momenta {
    double p[3] = {0, 0, 0}, l[3] = {0, 0, 0}, kinetic = 0, potential = 0;
};
inline Momenta momenta(const HostParticles& h, const std::vector<std::uint32_t>& ids, double mass, Vec3 gravity) {
    Momenta m;
    for (std::uint32_t i : ids) {
        const Vec3 x = h.position[i], v = h.velocity[i];
        m.p[0] += mass * v.x, m.p[1] += mass * v.y, m.p[2] += mass * v.z;
        const Vec3 c = cross(x, v);
        m.l[0] += mass * c.x, m.l[1] += mass * c.y, m.l[2] += mass * c.z;
        m.kinetic += 0.5 * mass * double(norm2(v));
        m.potential -= mass * double(dot(gravity, x));
    }
    return m;
}

// Average spacing of upward crossings of the mean (in samples), -1 with fewer than 2 crossings
// after the first `skip` samples.
inline double period_in_samples(const std::vector<double>& y, std::size_t skip = 0) {
    double mean = 0;
    for (std::size_t k = skip; k < y.size(); ++k) mean += y[k];
    mean /= double(y.size() - skip);
    std::vector<double> ups;
    for (std::size_t k = skip + 1; k < y.size(); ++k)
        if (y[k - 1] < mean && y[k] >= mean) ups.push_back(double(k - 1) + (mean - y[k - 1]) / (y[k] - y[k - 1]));
    if (ups.size() < 2) return -1;
    return (ups.back() - ups.front()) / double(ups.size() - 1);
}

// The pinned cantilever of scenes/cantilever.json, sized for tests: a box beam clamped at x < x0.
struct Cantilever {
    double period_s = -1;   // of the tip's vertical motion
    double sag = 0;         // mean tip displacement below rest, m
    double amplitude = 0;   // half of max - min of the tip height
    bool finite = true;
};
// `substep`: solver.solid_substep; negative keeps the default. `tail`: the share of the run at its
// end that sag and amplitude are taken over (1: all of it).
inline Cantilever run_cantilever(int w, Real alpha, Real dt, double seconds, Vec3 size = Vec3{0.3f, 0.1f, 0.1f},
                                 Real substep = -1, Real body_damping = 0, double tail = 1) {
    SimulationSetup s = empty_setup(Vec3{0, 0, 0}, Vec3{1, 1, 0.4f}, dt, Vec3{0, -9.81f, 0});
    if (substep >= 0) s.params.solver.solid_substep = substep;
    const Vec3 c{Real(0.1) + size.x / 2, Real(0.7), Real(0.2)};
    const Real clamp_x = Real(0.1) + Real(0.04);
    SolidSetup body = solid(SolidKind::kElastic, 1000, w, alpha);
    body.body_damping = body_damping;
    add(s, box_mesh(size, c), body, Vec3{0, 0, 0}, [clamp_x](const Vec3& x) { return x.x < clamp_x; });
    const std::vector<std::uint32_t> ids = ibps(s);
    std::uint32_t tip = ids[0];
    for (std::uint32_t i : ids)
        if (s.position[i].x > s.position[tip].x + 1e-6 ||
            (std::fabs(s.position[i].x - s.position[tip].x) < 1e-6 && std::fabs(s.position[i].y - c.y) < std::fabs(s.position[tip].y - c.y)))
            tip = i;
    const double y0 = s.position[tip].y;
    auto sim = make_openmp(s);
    HostParticles h;
    std::vector<double> y;
    const long steps = std::lround(seconds / dt);
    for (long k = 0; k < steps; ++k) {
        sim->step();
        sim->download(h);
        y.push_back(h.position[tip].y);
    }
    Cantilever r;
    double lo = 1e30, hi = -1e30, mean = 0;
    const std::size_t from = y.size() - std::size_t(std::lround(tail * double(y.size())));
    for (std::size_t k = 0; k < y.size(); ++k) r.finite = r.finite && std::isfinite(y[k]);
    for (std::size_t k = from; k < y.size(); ++k) lo = std::min(lo, y[k]), hi = std::max(hi, y[k]), mean += y[k];
    mean /= double(y.size() - from);
    r.sag = y0 - mean;
    r.amplitude = 0.5 * (hi - lo);
    const double p = period_in_samples(y);
    r.period_s = p > 0 ? p * dt : -1;
    return r;
}

}  // namespace lsm_test
