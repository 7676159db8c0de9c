// Bitwise reproducibility on one backend, and agreement between CUDA and OpenMP; the solver's
// step controls (solver.eta_max, the CFL time step).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "backend/backend.hpp"
#include "simulation/factory.hpp"
#include "test_setups.hpp"
#include "tests/skip.hpp"

using namespace mw;

namespace {
// About 10k fluid particles: a 0.2 x 0.4 x 0.12 m column at r0 = 0.01 in a 1 x 0.5 x 0.12 m tank,
// with the cubic spline at h = 2 r0 or another kernel and support.
SimulationSetup small_dam_break(KernelKind kernel = KernelKind::kCubicSpline, Real support_in_r0 = 2) {
    SimulationSetup setup = test::fluid_in_box({0, 0, 0}, {1.0f, 0.5f, 0.12f}, {0, 0, 0}, {0.2f, 0.4f, 0.12f}, 0.01f,
                                               0.001f, true, support_in_r0, kernel);
    setup.params.fluid.viscosity = 0.01f;
    return setup;
}
bool bitwise_equal(const HostParticles& a, const HostParticles& b) {
    return a.position.size() == b.position.size() &&
           !std::memcmp(a.position.data(), b.position.data(), a.position.size() * sizeof(Vec3)) &&
           !std::memcmp(a.velocity.data(), b.velocity.data(), a.velocity.size() * sizeof(Vec3)) &&
           !std::memcmp(a.density.data(), b.density.data(), a.density.size() * sizeof(Real)) &&
           !std::memcmp(a.pressure.data(), b.pressure.data(), a.pressure.size() * sizeof(Real));
}
}  // namespace

TEST_CASE("two runs on the same backend are bitwise identical, whatever the thread count") {
    // The OpenMP sort runs on one thread below 1 << 14 moving particles (kParallelMin in
    // backend/openmp/backend_openmp.cpp), so the column is larger than that: 0.19 x 0.41 x 0.23 m
    // at r0 = 0.01, 19 x 41 x 23 = 17,917 fluid particles (the only moving ones), a count that
    // neither 2 nor 3 threads divide evenly: every loop and the sort get chunks of unequal size.
    SimulationSetup setup =
        test::fluid_in_box({0, 0, 0}, {1.0f, 0.5f, 0.23f}, {0, 0, 0}, {0.19f, 0.41f, 0.23f}, 0.01f, 0.001f);
    setup.params.fluid.viscosity = 0.01f;
    const long fluid = std::count(setup.type.begin(), setup.type.end(), std::uint8_t(kFluid));
    REQUIRE(fluid > (1 << 14));
    REQUIRE(fluid % 2 != 0);
    REQUIRE(fluid % 3 != 0);
    const int steps = 20;
    auto run_on = [&](int threads) {
        auto sim = create_openmp_simulation(setup, threads);
        CHECK(sim->device_name().rfind(std::to_string(threads) + (threads == 1 ? " OpenMP thread " : " OpenMP threads "), 0) == 0);
        return test::run_steps(*sim, steps);
    };
    const HostParticles first = run_on(2);
    const HostParticles second = run_on(2);
    const HostParticles one_thread = run_on(1);
    const HostParticles three_threads = run_on(3);
    CHECK(bitwise_equal(first, second));
    CHECK(bitwise_equal(first, one_thread));
    CHECK(bitwise_equal(first, three_threads));
    // And the run did something: the column has started to fall (g t = 0.2 m/s after 20 steps).
    double max_speed = 0;
    for (const Vec3& v : first.velocity) max_speed = std::max(max_speed, double(norm(v)));
    CHECK(max_speed > 0.1);
}

// The same on CUDA: every stage is a gather, the radix sort is stable, the only atomic counts
// integers, and CUB's reductions are run-to-run deterministic on one GPU (its documented default),
// so two runs must agree bit for bit. 50 steps, as for the comparison with OpenMP below.
TEST_CASE("CUDA against CUDA: two runs are bitwise identical (grid gathers and neighbour lists)") {
    if (!cuda_backend_info().available) {
        MW_SKIP(cuda_backend_info().description);
        return;
    }
    for (const auto lists : test::kGatherModes) {
        CAPTURE(test::gather_mode_name(lists));
        SimulationSetup setup = small_dam_break();
        setup.params.neighbors.lists = lists;
        const HostParticles first = test::run_steps(*create_cuda_simulation(setup), 50);
        const HostParticles second = test::run_steps(*create_cuda_simulation(setup), 50);
        CHECK(bitwise_equal(first, second));
        double max_speed = 0;
        for (const Vec3& v : first.velocity) max_speed = std::max(max_speed, double(norm(v)));
        CHECK(max_speed > 0.1);  // the column is falling: not a comparison of two resting states
    }
}

namespace {
void compare_cuda_with_openmp(NeighborParams::Lists lists, KernelKind kernel = KernelKind::kCubicSpline,
                              Real support_in_r0 = 2) {
    if (!cuda_backend_info().available) {
        MW_SKIP(cuda_backend_info().description);
        return;
    }
    SimulationSetup setup = small_dam_break(kernel, support_in_r0);
    setup.params.neighbors.lists = lists;  // the same neighbour structure on both sides
    const test::OpenmpAndCuda runs = test::run_openmp_and_cuda(setup, 50);
    const HostParticles &cpu = runs.openmp, &gpu = runs.cuda;
    REQUIRE(cpu.position.size() == gpu.position.size());
    const double domain_size = norm(setup.params.domain_max - setup.params.domain_min);
    const double worst = test::largest_position_difference(cpu, gpu);
    MESSAGE("largest position difference after 50 steps: " << worst << " m (" << worst / domain_size << " of the domain)");
    CHECK(worst < 1e-4 * domain_size);
    // And the run did something: a comparison of two resting columns would prove little.
    double max_speed = 0;
    for (const Vec3& v : gpu.velocity) max_speed = std::max(max_speed, double(norm(v)));
    CHECK(max_speed > 0.1);
}
}  // namespace

TEST_CASE("CUDA and OpenMP agree on a 10k-particle dam break, grid gathers") {
    compare_cuda_with_openmp(NeighborParams::Lists::kOff);
}

TEST_CASE("CUDA and OpenMP agree on a 10k-particle dam break, neighbour lists") {
    compare_cuda_with_openmp(NeighborParams::Lists::kOn);
}

// The other kernel is another instantiation of the whole solver on each backend.
TEST_CASE("CUDA and OpenMP agree on a 10k-particle dam break, Wendland C2 at h = 2.5 r0, grid gathers") {
    compare_cuda_with_openmp(NeighborParams::Lists::kOff, KernelKind::kWendlandC2, 2.5);
}

// Lists hold the pairs within h at the start of a step; grid gathers also see pairs that come
// within h while PCISPH predicts (weights of order (Δt |v_ij| / h)³), so the two differ by rounding-
// sized amounts that grow slowly, not bitwise.
TEST_CASE("neighbour lists and grid gathers give the same dam break") {
    SimulationSetup setup = small_dam_break();
    setup.params.neighbors.lists = NeighborParams::Lists::kOn;
    const HostParticles with_lists = test::run_steps(*create_openmp_simulation(setup, 0), 50);
    setup.params.neighbors.lists = NeighborParams::Lists::kOff;
    const HostParticles with_grid = test::run_steps(*create_openmp_simulation(setup, 0), 50);
    const double worst = test::largest_position_difference(with_lists, with_grid);
    MESSAGE("largest position difference, lists against grid, after 50 steps: " << worst << " m");
    CHECK(worst < 1e-3 * setup.params.fluid.spacing);
}

TEST_CASE("solver.eta_max bounds the peak density error of every step") {
    SimulationSetup setup = small_dam_break();
    auto free_run = create_openmp_simulation(setup, 0);
    setup.params.solver.eta_max = Real(0.005);
    auto bounded_run = create_openmp_simulation(setup, 0);
    const int steps = 60;
    long free_iterations = 0, bounded_iterations = 0;
    int checked_steps = 0, most_iterations = 0;
    double free_peak = 0;
    for (int s = 0; s < steps; ++s) {
        free_run->step();
        bounded_run->step();
        free_iterations += free_run->last_report().iterations;
        free_peak = std::max(free_peak, free_run->last_report().density_error_max);
        const StepReport& r = bounded_run->last_report();
        bounded_iterations += r.iterations;
        most_iterations = std::max(most_iterations, r.iterations);
        // A step that ran out of iterations, or stopped because its iteration diverged, did not
        // meet the rule: its peak is not bounded, and it is counted below instead.
        if (!r.unconverged && !r.diverged) {
            CHECK(r.density_error_max <= 0.005);
            ++checked_steps;
        }
    }
    MESSAGE("peak error without eta_max " << 100 * free_peak << "%; iterations " << free_iterations << " without, "
                                          << bounded_iterations << " with eta_max 0.5% (at most " << most_iterations
                                          << " in a step); bound checked on " << checked_steps << " of " << steps
                                          << " steps");
    // The rule was met on (nearly) every step: otherwise the check above would have run on none,
    // and passed. Measured: all 60 steps, at most 18 iterations in a step (max_iterations 100).
    CHECK(checked_steps >= steps - 5);
    CHECK(most_iterations < setup.params.solver.max_iterations);
    CHECK(free_peak > 0.005);                         // the bound had something to do
    CHECK(bounded_iterations > free_iterations);      // and it cost iterations
}

namespace {
// A 10 x 10 x 10 block of fluid at r0 = 0.02 alone in a 1 m box (no walls), every particle at
// `velocity`; CFL time steps (cfl 0.4, largest step 0.01 s), no gravity unless asked.
SimulationSetup free_block_cfl(Vec3 velocity, Vec3 gravity = Vec3{0, 0, 0}) {
    SimulationSetup setup =
        test::fluid_in_box({0, 0, 0}, {1, 1, 1}, {0.3f, 0.3f, 0.3f}, {0.5f, 0.5f, 0.5f}, 0.02f, 0.01f, false);
    setup.params.gravity = gravity;
    setup.params.solver.dt_mode = TimeStepMode::kCfl;
    setup.params.solver.cfl_number = 0.4f;
    setup.params.solver.dt_min = 1e-6f;
    setup.velocity.assign(setup.position.size(), velocity);
    return setup;
}
// Steps the simulation, returns the reported steps; checks that time() is their sum.
std::vector<StepReport> cfl_steps(const SimulationSetup& setup, int steps) {
    auto sim = create_openmp_simulation(setup, 0);
    std::vector<StepReport> reports;
    double sum = 0;
    for (int s = 0; s < steps; ++s) {
        sim->step();
        reports.push_back(sim->last_report());
        sum += reports.back().dt;
    }
    // The same additions in the same order (double): equal but for a possible change of order.
    CHECK(sim->time() == doctest::Approx(sum).epsilon(1e-12));
    return reports;
}
}  // namespace

namespace {
// The distance a particle may move in a CFL step: the setup's cfl_number times its r0.
double cfl_r0(const SimulationParams& params) { return double(params.solver.cfl_number) * double(params.fluid.spacing); }
// The CFL bound under the setup's gravity g: the Δt with (v + g Δt) Δt = cfl r0.
double cfl_bound_under_gravity(const SimulationParams& params, double v) {
    const double g = -double(params.gravity.y);
    return 2 * cfl_r0(params) / (v + std::sqrt(v * v + 4 * g * cfl_r0(params)));
}
}  // namespace

TEST_CASE("CFL time steps follow the last step's largest speed and gravity, capped at dt and floored at dt_min") {
    // Without gravity Δt = cfl r0 / v_max.
    // Float parameters (0.4f * 0.02f / v in float): agreement to a few float roundings, relative
    // (scale 0: doctest's default scale of 1 would make this 1e-6 s, an eighth of the 8 ms step).
    // Measured: at most 5.5e-8, half a float ulp.
    const double rounding = 1e-6;

    SUBCASE("a block moving at 1 m/s steps 0.4 r0 / (1 m/s) = 0.008 s") {
        const SimulationSetup setup = free_block_cfl({1, 0, 0});
        const std::vector<StepReport> r = cfl_steps(setup, 5);
        // The first step uses the initial speeds, every later one the speed the step before reported.
        CHECK(r[0].dt == doctest::Approx(cfl_r0(setup.params) / 1.0).epsilon(rounding).scale(0));
        for (std::size_t k = 1; k < r.size(); ++k) {
            // A free block at rest density translates: no pressure, no viscosity, no gravity.
            CHECK(r[k - 1].max_speed == doctest::Approx(1.0).epsilon(1e-4));
            CHECK(r[k].dt == doctest::Approx(cfl_r0(setup.params) / r[k - 1].max_speed).epsilon(rounding).scale(0));
        }
    }
    // Below, the step is one of the parameters itself, passed through: compared exactly.
    SUBCASE("at rest the step is the largest step, dt") {
        const SimulationSetup setup = free_block_cfl({0, 0, 0});
        for (const StepReport& r : cfl_steps(setup, 3)) CHECK(r.dt == double(setup.params.solver.dt));
    }
    SUBCASE("a solid moving past resting fluid bounds the step as fluid at its speed would") {
        // Its particles must not cross more than cfl r0 of the fluid in a step either. A rigid cube
        // at 2 m/s (no gravity, away from the fluid and the domain's faces) keeps its speed, so
        // every step is cfl r0 / (2 m/s) = 0.004 s, not the largest step of 0.01 s that the
        // fluid at rest alone would allow.
        SimulationSetup setup = free_block_cfl({0, 0, 0});
        SolidSetup cube;
        cube.name = "cube";
        cube.kind = SolidKind::kRigid;
        test::add_box_solid(setup, Vec3d{0.1, 0.1, 0.1}, Vec3d{0.75, 0.4, 0.4}, cube, Vec3{2, 0, 0});
        for (const StepReport& r : cfl_steps(setup, 4)) {
            CHECK(r.max_speed < 1e-4);  // the block's edges settle by micrometres per second
            CHECK(r.solid_max_speed == doctest::Approx(2.0).epsilon(1e-4));
            CHECK(r.dt == doctest::Approx(cfl_r0(setup.params) / 2.0).epsilon(1e-4).scale(0));
        }
    }
    SUBCASE("at a huge speed the step is floored at min(dt_min, dt)") {
        // 1e4 m/s: cfl r0 / v = 8e-7 s, below dt_min = 1e-6 s.
        const SimulationSetup fast = free_block_cfl({0, 1e4f, 0});
        for (const StepReport& r : cfl_steps(fast, 2)) CHECK(r.dt == double(fast.params.solver.dt_min));
        // A floor above dt never lifts the step above dt: at 2 m/s (CFL 0.004 s) with dt_min 0.02 s
        // the step is dt = 0.01 s.
        SimulationSetup setup = free_block_cfl({2, 0, 0});
        setup.params.solver.dt_min = 0.02f;
        for (const StepReport& r : cfl_steps(setup, 2)) CHECK(r.dt == double(setup.params.solver.dt));
    }
    SUBCASE("from rest under gravity the first step is the free-fall bound, sqrt(cfl r0 / g)") {
        // A step of the largest size, 0.05 s, would drop the block g Δt² = 2.5 cm = 1.2 r0 at once.
        SimulationSetup setup = free_block_cfl({0, 0, 0}, {0, -9.81f, 0});
        setup.params.solver.dt = 0.05f;
        const std::vector<StepReport> r = cfl_steps(setup, 1);
        CHECK(r[0].dt == doctest::Approx(std::sqrt(cfl_r0(setup.params) / 9.81)).epsilon(rounding).scale(0));
        CHECK(r[0].dt < 0.05);
    }
    SUBCASE("each step uses the speed reached by the step before (free fall of a lone particle)") {
        // One particle has no neighbours (its density is below ρ0, so no pressure): it falls
        // freely, v_k = v_{k-1} + g Δt_k, and Δt_k = min(dt, max(dt_min, b(v_{k-1}))), where
        // b(v) = 2 cfl r0 / (v + √(v² + 4 g cfl r0)) solves (v + g b) b = cfl r0: the particle
        // moves at most cfl r0 in the step. b(0) = 0.029 s is above dt = 0.01 s, and b takes over
        // once v > 0.70 m/s (after 8 steps of 0.01 s).
        SimulationSetup setup = free_block_cfl({0, 0, 0}, {0, -9.81f, 0});
        setup.position = {{0.5f, 0.9f, 0.5f}};
        setup.velocity = {{0, 0, 0}};
        setup.type = {kFluid};
        setup.object = {-1};
        const std::vector<StepReport> r = cfl_steps(setup, 30);
        double v = 0;
        int cfl_limited = 0;
        for (const StepReport& report : r) {
            const double dt = std::min(0.01, std::max(1e-6, cfl_bound_under_gravity(setup.params, v)));
            cfl_limited += dt < 0.01;
            v += 9.81 * dt;
            // Float velocities summed over 30 steps: relative rounding of order 30 x 6e-8 (scale 0,
            // relative: the default scale of 1 would allow 1e-5 s on steps of 3 to 10 ms). Measured:
            // at most 1.2e-7 on the step, 1.0e-7 on the speed.
            CHECK(report.dt == doctest::Approx(dt).epsilon(1e-5).scale(0));
            CHECK(report.max_speed == doctest::Approx(v).epsilon(1e-5).scale(0));
        }
        CHECK(cfl_limited >= 15);  // most of the run tests the CFL branch, not the cap
    }
}

TEST_CASE("CFL retries: the largest step grows back by at most a quarter, by less when retries come close together") {
    // The resting column of scenes/hydrostatic_column.json (2,000 particles, 20 layers) with a
    // largest step of 0.01 s, far above the ~4 ms its PCISPH holds: steps keep diverging and are
    // retried at half the step (docs/solver.md, "Time step").
    SimulationSetup setup =
        test::fluid_in_box({0, 0, 0}, {0.2f, 0.6f, 0.2f}, {0, 0, 0}, {0.2f, 0.4f, 0.2f}, 0.02f, 0.01f);
    setup.params.gravity = {0, -9.81f, 0};
    setup.params.solver.dt_mode = TimeStepMode::kCfl;
    const std::vector<StepReport> r = cfl_steps(setup, 250);
    int retried = 0, close_pairs = 0;
    long last_retry = -1000;
    bool last_was_close = false;
    int checked = 0, checked_close = 0;
    for (std::size_t k = 0; k < r.size(); ++k) {
        CAPTURE(k);
        CHECK(!r[k].diverged);
        if (r[k].retries > 0) {
            ++retried;
            last_was_close = long(k) - last_retry < 20;
            close_pairs += last_was_close;
            last_retry = long(k);
            continue;
        }
        // No retry in step k: its step is at most the growth times the last step's limit (the CFL
        // bound and the cap only lower it). Where the step before was below its own CFL bound, it
        // was that limit (or the cap), so the ratio of the two steps is at most the growth: 1.25,
        // and 1.125 for the 20 steps after a retry that came within 20 steps of the one before.
        if (k == 0) continue;
        const double v_before = k >= 2 ? r[k - 2].max_speed : 0.0;
        if (r[k - 1].dt > cfl_bound_under_gravity(setup.params, v_before) * (1 - 1e-5)) continue;  // it was CFL-bound
        const double growth = r[k].dt / r[k - 1].dt;
        ++checked;
        CHECK(growth <= 1.25 * (1 + 1e-6));
        if (last_was_close && long(k) - last_retry < 20) {
            ++checked_close;
            CHECK(growth <= 1.125 * (1 + 1e-6));
        }
    }
    MESSAGE("growth checked on " << checked << " steps, " << checked_close << " after close retries");
    REQUIRE(checked_close > 0);  // the rule above had something to check
    MESSAGE(retried << " of " << r.size() << " steps retried, " << close_pairs << " within 20 steps of the last");
    // With a growth of a quarter after every retry, 23% of this column's steps were retried (109
    // of 478 over 2 s); with the adaptive growth 6% (30 of 479).
    CHECK(retried < r.size() / 8);
}
