// Lattice shape matching: polar decomposition, rest state, goals under rigid motion, momentum,
// the cantilever, stability at the paper's Δt, and the CUDA/OpenMP comparison.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <sstream>

#include "algorithms/polar_decomposition.hpp"
#include "algorithms/solid_bodies.hpp"
#include "lsm_helpers.hpp"
#include "sampling/obj_loader.hpp"

using namespace mw;
using namespace lsm_test;

namespace {

Mat3 rotation_about(Vec3 axis, double angle) {
    const Real n = norm(axis);
    const Real s = Real(std::sin(angle / 2));
    return quat_to_mat3(Quat{Real(std::cos(angle / 2)), axis.x / n * s, axis.y / n * s, axis.z / n * s});
}
double max_abs_diff(const Mat3& a, const Mat3& b) {
    double m = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m = std::max(m, double(std::fabs(a.m[i][j] - b.m[i][j])));
    return m;
}

}  // namespace

TEST_CASE("polar decomposition: rotation of R·S, flat and line-like matrices, identity kept exactly") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int trial = 0; trial < 200; ++trial) {
        const Mat3 Q = rotation_about(Vec3{Real(u(rng)), Real(u(rng)), Real(u(rng)) + Real(1.5)}, 3.0 * u(rng));
        // S symmetric positive semi-definite; rank 3, 2 (flat region) or 1 (line region).
        const int rank = 1 + trial % 3;
        Mat3 S = mat3_zero();
        for (int k = 0; k < rank; ++k) {
            const Vec3 d{Real(u(rng)), Real(u(rng)), Real(u(rng))};
            S = S + outer(d, d);
        }
        if (rank == 3) S = S + Real(0.2) * mat3_identity();  // well conditioned
        const Mat3 A = Q * S;
        // Warm start: near the answer, as in a time step (a rotation of up to about 0.5 rad).
        const Mat3 warm_m = Q * rotation_about(Vec3{Real(u(rng)), Real(u(rng)), Real(1)}, 0.5 * u(rng));
        // Convert the warm matrix to a quaternion by iterating from identity on it (it is a rotation).
        const Quat warm = polar_rotation(warm_m, quat_identity(), 100);
        const Quat q = polar_rotation(A, warm, 100);
        const Mat3 R = quat_to_mat3(q);
        // R must be a rotation and Rᵀ A symmetric (positive semi-definite) in every case.
        CHECK(max_abs_diff(transpose(R) * R, mat3_identity()) < 1e-5);
        const Mat3 RtA = transpose(R) * A;
        const double size = double(S.m[0][0] + S.m[1][1] + S.m[2][2]);
        CHECK(max_abs_diff(RtA, transpose(RtA)) < 2e-3 * size);
        CHECK(double(RtA.m[0][0] + RtA.m[1][1] + RtA.m[2][2]) > 0.99 * size);  // trace(RᵀA) maximal
        if (rank == 3) CHECK(max_abs_diff(R, Q) < 2e-4);
    }
    // A symmetric matrix from the identity: exactly the identity (keeps bodies at rest bitwise).
    const Mat3 S{{{2, 0.3f, 0.1f}, {0.3f, 1, 0.2f}, {0.1f, 0.2f, 0.5f}}};
    const Quat q = polar_rotation(S, quat_identity());
    CHECK(q.w == 1);
    CHECK(q.x == 0);
    CHECK(q.y == 0);
    CHECK(q.z == 0);
}

TEST_CASE("a body at rest with no forces stays at rest for 1000 steps") {
    SimulationSetup s = empty_setup(Vec3{0, 0, 0}, Vec3{1, 1, 1}, Real(0.01), Vec3{0, 0, 0});
    add(s, box_mesh(Vec3{0.16f, 0.1f, 0.12f}, Vec3{0.5f, 0.5f, 0.5f}, Vec3{10, 20, 30}), solid(SolidKind::kElastic, 1000, 2, 0.5f, 1));
    auto sim = make_openmp(s);
    for (int k = 0; k < 1000; ++k) sim->step();
    HostParticles h;
    sim->download(h);
    double drift = 0;
    for (std::size_t i = 0; i < s.position.size(); ++i) drift = std::max(drift, double(norm(h.position[i] - s.position[i])));
    const double r0 = s.params.fluid.spacing;
    MESSAGE("largest drift after 1000 steps (IBPs, SBPs, GPs): " << drift / r0 << " r0");
    CHECK(drift < 1e-5 * r0);
}

TEST_CASE("goals reproduce a rigid translation plus rotation of the rest shape") {
    for (SolidKind kind : {SolidKind::kElastic, SolidKind::kRigid}) {
        SimulationSetup s = empty_setup(Vec3{0, 0, 0}, Vec3{1, 1, 1}, Real(0.01), Vec3{0, 0, 0});
        add(s, box_mesh(Vec3{0.2f, 0.1f, 0.04f}, Vec3{0.5f, 0.5f, 0.5f}), solid(kind, 1000, 2, 1));
        const std::size_t n = s.position.size();
        openmp_backend::ParticleStore store;
        store.resize(n, n);
        std::vector<std::uint32_t> order(n);
        for (std::size_t i = 0; i < n; ++i) order[i] = std::uint32_t(i);
        store.id.upload(order);
        store.type.upload(s.type);
        store.position.upload(s.position);
        store.velocity.upload(s.velocity);
        openmp_backend::SolidBodies bodies;
        bodies.init(s, order, store);
        // Move every particle rigidly: x = Q (x0 - p) + p + T.
        const Mat3 Q = rotation_about(Vec3{1, 2, 3}, 1.1);
        const Vec3 p{0.5f, 0.5f, 0.5f}, T{0.1f, -0.05f, 0.2f};
        std::vector<Vec3> moved(n);
        for (std::size_t i = 0; i < n; ++i) moved[i] = Q * (s.position[i] - p) + p + T;
        store.position.upload(moved);
        std::vector<Vec3> goals = bodies.goals(store);
        goals = bodies.goals(store);  // a second round: the warm start is now the answer
        const std::vector<std::uint32_t> ids = ibps(s);
        double err = 0;
        for (std::size_t k = 0; k < ids.size(); ++k) err = std::max(err, double(norm(goals[k] - moved[ids[k]])));
        MESSAGE(std::string(kind == SolidKind::kRigid ? "rigid" : "elastic") << ": largest goal error " << err / 0.02 << " r0");
        CHECK(err < 1e-3 * 0.02);  // 1e-3 r0 (float rounding of coordinates near 0.5 m)
    }
}

TEST_CASE("regions summed in chunks agree with one-thread sums (rigid and elastic, damped)") {
    for (SolidKind kind : {SolidKind::kRigid, SolidKind::kElastic}) {
        SimulationSetup s = empty_setup(Vec3{0, 0, 0}, Vec3{1, 1, 1}, Real(0.005), Vec3{0, -9.81f, 0}, Real(0.01));
        add(s, box_mesh(Vec3{0.3f, 0.2f, 0.1f}, Vec3{0.5f, 0.5f, 0.5f}), solid(kind, 1000, 2, 0.5f, 5));
        // A deformed, moving start: the sums are then all non-trivial.
        std::mt19937 rng(11);
        std::uniform_real_distribution<double> u(-1, 1);
        const Mat3 Q = rotation_about(Vec3{1, 2, 3}, 0.7);
        const Vec3 p{0.5f, 0.5f, 0.5f};
        std::vector<Vec3> moved(s.position.size()), velocity(s.position.size());
        for (std::size_t i = 0; i < moved.size(); ++i) {
            const Vec3 jitter{Real(u(rng)), Real(u(rng)), Real(u(rng))};
            moved[i] = Q * (s.position[i] - p) + p + Real(0.002) * jitter;
            velocity[i] = Vec3{0.3f, 0, -0.1f} + cross(Vec3{0, 2, 1}, s.position[i] - p) + Real(0.1) * jitter;
        }
        const std::size_t n = s.position.size();
        std::vector<std::uint32_t> order(n);
        for (std::size_t i = 0; i < n; ++i) order[i] = std::uint32_t(i);
        // The same body twice: regions summed by one thread each, and in chunks (the elastic
        // regions, 125 members, are chunked only when the limit is lowered below that).
        const std::size_t chunked_limit = kind == SolidKind::kRigid ? kRegionSerialMembers : 64;
        std::vector<Vec3> goals[2], velocities[2];
        std::size_t chunks[2] = {0, 0};
        for (int variant = 0; variant < 2; ++variant) {
            openmp_backend::ParticleStore store;
            store.resize(n, n);
            store.id.upload(order);
            store.type.upload(s.type);
            store.position.upload(s.position);
            store.velocity.upload(velocity);
            openmp_backend::SolidBodies bodies;
            bodies.init(s, order, store, variant == 0 ? std::size_t(-1) : chunked_limit);
            chunks[variant] = bodies.region_chunk_count();
            store.position.upload(moved);
            goals[variant] = bodies.goals(store);
            bodies.step(store, s.params.solver.dt, s.params.gravity, s.params.domain_min, s.params.domain_max);
            velocities[variant] = store.velocity.to_host();
        }
        double goal_diff = 0, velocity_diff = 0, speed = 0;
        for (std::size_t k = 0; k < goals[0].size(); ++k) goal_diff = std::max(goal_diff, double(norm(goals[0][k] - goals[1][k])));
        for (std::size_t i = 0; i < n; ++i) {
            velocity_diff = std::max(velocity_diff, double(norm(velocities[0][i] - velocities[1][i])));
            speed = std::max(speed, double(norm(velocities[0][i])));
        }
        MESSAGE(std::string(kind == SolidKind::kRigid ? "rigid" : "elastic") << ", " << goals[0].size() << " IBPs in " << chunks[1]
                << " chunks: goals differ by " << goal_diff / 0.01 << " r0, velocities by " << velocity_diff / speed
                << " of the top speed");
        CHECK(chunks[0] == 0);
        CHECK(chunks[1] > (kind == SolidKind::kRigid ? 8u : 1000u));
        // Rounding only: float sums of 6000 terms in another order (the elastic regions, one
        // chunk each in the same order, come out bitwise equal). The velocity update divides the
        // goal offset by Δt, which scales the difference up.
        CHECK(goal_diff < 1e-4 * 0.01);
        CHECK(velocity_diff < 2e-4 * speed);
    }
}

TEST_CASE("momentum with no external force: linear within 2e-4, angular within 1e-3 (relative, 400 steps)") {
    SimulationSetup s = empty_setup(Vec3{-1, -1, -1}, Vec3{1, 1, 1}, Real(0.005), Vec3{0, 0, 0});
    add(s, box_mesh(Vec3{0.24f, 0.12f, 0.1f}, Vec3{0, 0, 0}, Vec3{0, 0, 25}), solid(SolidKind::kElastic, 500, 1, 0.7f));
    // Spin, drift and a deformation (random velocities) to start with.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    const Vec3 omega{0.5f, 2.0f, -1.0f}, V{0.3f, 0.1f, -0.2f};
    for (std::size_t i = 0; i < s.position.size(); ++i)
        s.velocity[i] = V + cross(omega, s.position[i]) + Real(0.2) * Vec3{Real(u(rng)), Real(u(rng)), Real(u(rng))};
    const std::vector<std::uint32_t> ids = ibps(s);
    const double mass = 500 * std::pow(0.02, 3);
    HostParticles h;
    auto sim = make_openmp(s);
    sim->download(h);
    const Momenta m0 = momenta(h, ids, mass, Vec3{0, 0, 0});
    double worst_p = 0, worst_l = 0;
    const double p_scale = std::sqrt(m0.p[0] * m0.p[0] + m0.p[1] * m0.p[1] + m0.p[2] * m0.p[2]);
    const double l_scale = std::sqrt(m0.l[0] * m0.l[0] + m0.l[1] * m0.l[1] + m0.l[2] * m0.l[2]);
    for (int k = 0; k < 400; ++k) {
        sim->step();
        if (k % 20 != 19) continue;
        sim->download(h);
        const Momenta m = momenta(h, ids, mass, Vec3{0, 0, 0});
        for (int a = 0; a < 3; ++a) {
            worst_p = std::max(worst_p, std::fabs(m.p[a] - m0.p[a]) / p_scale);
            worst_l = std::max(worst_l, std::fabs(m.l[a] - m0.l[a]) / l_scale);
        }
    }
    MESSAGE("relative momentum error over 400 steps: linear " << worst_p << ", angular " << worst_l);
    CHECK(worst_p < 2e-4);
    CHECK(worst_l < 1e-3);
}

TEST_CASE("damping conserves linear momentum and removes deformation energy") {
    SimulationSetup s = empty_setup(Vec3{-1, -1, -1}, Vec3{1, 1, 1}, Real(0.005), Vec3{0, 0, 0});
    add(s, box_mesh(Vec3{0.2f, 0.1f, 0.1f}, Vec3{0, 0, 0}), solid(SolidKind::kElastic, 1000, 1, 0.5f, 5));
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    for (auto& v : s.velocity) v = Vec3{0.2f, 0, 0} + Real(0.3) * Vec3{Real(u(rng)), Real(u(rng)), Real(u(rng))};
    const std::vector<std::uint32_t> ids = ibps(s);
    const double mass = 1000 * std::pow(0.02, 3);
    HostParticles h;
    auto sim = make_openmp(s);
    sim->download(h);
    const Momenta m0 = momenta(h, ids, mass, Vec3{0, 0, 0});
    for (int k = 0; k < 400; ++k) sim->step();
    sim->download(h);
    const Momenta m1 = momenta(h, ids, mass, Vec3{0, 0, 0});
    CHECK(std::fabs(m1.p[0] - m0.p[0]) < 2e-4 * std::fabs(m0.p[0]));
    // What is left is (nearly) the translation's kinetic energy.
    const double translation = 0.5 * m0.p[0] * m0.p[0] / (mass * double(ids.size()));
    MESSAGE("kinetic energy: start " << m0.kinetic << " J, after 2 s " << m1.kinetic << " J, translation " << translation << " J");
    // (the random start also holds some rigid rotation, which damping keeps)
    CHECK(m1.kinetic - translation < 0.05 * (m0.kinetic - translation));
}

TEST_CASE("pinned cantilever sags, oscillates, and its period shortens as w or alpha grows") {
    const Real dt = Real(0.002);
    const Cantilever base = run_cantilever(2, Real(0.5), dt, 1.5);
    const Cantilever wider = run_cantilever(3, Real(0.5), dt, 1.5);
    const Cantilever stiffer = run_cantilever(2, Real(1.0), dt, 1.5);
    const Cantilever softer = run_cantilever(1, Real(0.5), dt, 1.5);
    MESSAGE("periods (s): w1 a0.5 " << softer.period_s << ", w2 a0.5 " << base.period_s << ", w3 a0.5 " << wider.period_s
                                    << ", w2 a1 " << stiffer.period_s << "; sag w2 a0.5 " << base.sag << " m, amplitude "
                                    << base.amplitude << " m");
    for (const Cantilever* c : {&base, &wider, &stiffer, &softer}) {
        CHECK(c->finite);
        CHECK(c->sag > 0.002);
        CHECK(c->amplitude > 0.002);
        CHECK(c->period_s > 0);
    }
    CHECK(wider.period_s < base.period_s);
    CHECK(base.period_s < softer.period_s);
    CHECK(stiffer.period_s < base.period_s);
}

TEST_CASE("no NaN and bounded energy at dt = 0.03 s: densities 100 to 10000, and a plate two particles thick") {
    struct Case {
        const char* what;
        Vec3 size, rot;
        Real density;
    };
    const Case cases[] = {{"box, 100 kg/m3", Vec3{0.2f, 0.12f, 0.14f}, Vec3{20, 10, 35}, 100},
                          {"box, 10000 kg/m3", Vec3{0.2f, 0.12f, 0.14f}, Vec3{20, 10, 35}, 10000},
                          {"plate 2 particles thick, 1000 kg/m3", Vec3{0.3f, 0.04f, 0.24f}, Vec3{15, 0, 25}, 1000}};
    const Vec3 gravity{0, -9.81f, 0};
    for (const Case& c : cases) {
        SimulationSetup s = empty_setup(Vec3{0, 0, 0}, Vec3{1, 1, 1}, Real(0.03), gravity);
        add(s, box_mesh(c.size, Vec3{0.5f, 0.6f, 0.5f}, c.rot), solid(SolidKind::kElastic, c.density, 2, 1), Vec3{1, 0, 0.5f});
        const std::vector<std::uint32_t> ids = ibps(s);
        const double mass = c.density * std::pow(0.02, 3);
        HostParticles h;
        auto sim = make_openmp(s);
        sim->download(h);
        const Momenta m0 = momenta(h, ids, mass, gravity);
        const double e0 = m0.kinetic + m0.potential;
        double worst = -1e30;
        bool finite = true;
        for (int k = 0; k < 300; ++k) {
            sim->step();
            sim->download(h);
            const Momenta m = momenta(h, ids, mass, gravity);
            finite = finite && std::isfinite(m.kinetic) && std::isfinite(m.potential);
            worst = std::max(worst, (m.kinetic + m.potential - e0) / std::fabs(e0));
        }
        MESSAGE(std::string(c.what) << ": " << ids.size() << " IBPs, largest energy gain over 300 steps " << worst * 100 << " % of E0");
        CHECK(finite);
        CHECK(worst < 0.05);
    }
}

TEST_CASE("CUDA against OpenMP: swaying pinned bunny, 100 steps") {
    if (!cuda_backend_info().available) {
        MESSAGE("skipped: no CUDA device (" << cuda_backend_info().description << ")");
        return;
    }
    const std::string bunny = std::string(MW_SHARED_DIR) + "/assets/meshes/stanford-bunny.obj";
    TriangleMesh mesh;
    if (std::filesystem::exists(bunny)) {
        mesh = load_obj(bunny, false);
        MeshTransform t;
        const Aabb b = bounding_box(mesh);
        const double scale = 0.3 / b.extent().maxCoeff();
        t.scale = Vec3d(scale, scale, scale);
        t.translation = Vec3d(0.5, 0.2, 0.5) - scale * b.center();
        apply_transform(mesh, t);
    } else {
        MESSAGE("bunny mesh not found; using a sphere");
        mesh = box_mesh(Vec3{0.2f, 0.2f, 0.2f}, Vec3{0.5f, 0.2f, 0.5f});
    }
    SimulationSetup s = empty_setup(Vec3{0, 0, 0}, Vec3{1, 1, 1}, Real(0.01), Vec3{-3, -9.81f, 0});
    add(s, mesh, solid(SolidKind::kElastic, 1000, 2, 0.5f), Vec3{0, 0, 0}, [](const Vec3& x) { return x.y < 0.1; });
    auto a = make_openmp(s);
    auto b = create_cuda_simulation(s);
    for (int k = 0; k < 100; ++k) a->step(), b->step();
    HostParticles ha, hb;
    a->download(ha);
    b->download(hb);
    double err = 0;
    for (std::size_t i = 0; i < s.position.size(); ++i) err = std::max(err, double(norm(ha.position[i] - hb.position[i])));
    MESSAGE("largest CUDA/OpenMP position difference: " << err / 0.3 << " of the object's size");
    CHECK(err < 1e-4 * 0.3);
}

TEST_CASE("cantilever period table: the period shortens as w or alpha grows") {
    // Prints the tables of docs/lsm.md. At dt = 0.002 s it checks monotonicity over the whole
    // grid; at dt = 0.03 s (the paper's step) LSM's per-step stiffness makes the soft settings
    // droop without a measurable oscillation (period printed as -1), so only finiteness is checked.
    const int ws[] = {1, 2, 3};
    const Real alphas[] = {Real(0.25), Real(0.5), Real(1.0)};
    for (const Real dt : {Real(0.002), Real(0.03)}) {
        const double seconds = dt < Real(0.01) ? 2.0 : 12.0;
        double period[3][3];
        std::ostringstream table;
        table << "dt = " << dt << " s\n| w \\ alpha | 0.25 | 0.5 | 1.0 |\n|---|---|---|---|\n";
        for (int a = 0; a < 3; ++a)
            for (int k = 0; k < 3; ++k) {
                const Cantilever c = run_cantilever(ws[k], alphas[a], dt, seconds);
                CHECK(c.finite);
                period[k][a] = c.period_s;
            }
        for (int k = 0; k < 3; ++k) {
            table << "| " << ws[k] << " |";
            for (int a = 0; a < 3; ++a) table << " " << period[k][a] << " |";
            table << "\n";
        }
        MESSAGE(table.str());
        if (dt > Real(0.01)) continue;
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) {
                CAPTURE(dt);
                CAPTURE(k);
                CAPTURE(a);
                CHECK(period[k][a] > 0);
                if (k + 1 < 3) CHECK(period[k + 1][a] < period[k][a]);
                if (a + 1 < 3) CHECK(period[k][a + 1] < period[k][a]);
            }
    }
}
