// Bitwise reproducibility on one backend, and agreement between CUDA and OpenMP.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>

#include "backend/backend_registry.hpp"
#include "test_setups.hpp"

using namespace mw;

namespace {
// About 10k fluid particles: a 0.2 x 0.4 x 0.12 m column at r0 = 0.01 in a 1 x 0.5 x 0.12 m tank.
SimulationSetup small_dam_break() {
    SimulationSetup setup =
        test::fluid_in_box({0, 0, 0}, {1.0f, 0.5f, 0.12f}, {0, 0, 0}, {0.2f, 0.4f, 0.12f}, 0.01f, 0.001f);
    setup.params.fluid.viscosity = 0.01f;
    return setup;
}
HostParticles run(std::unique_ptr<Simulation> sim, int steps) {
    for (int s = 0; s < steps; ++s) sim->step();
    HostParticles p;
    sim->download(p);
    return p;
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
    const SimulationSetup setup = small_dam_break();
    const HostParticles first = run(create_openmp_simulation(setup, 2), 30);
    const HostParticles second = run(create_openmp_simulation(setup, 2), 30);
    const HostParticles one_thread = run(create_openmp_simulation(setup, 1), 30);
    CHECK(bitwise_equal(first, second));
    CHECK(bitwise_equal(first, one_thread));
    // And the run did something: the column has started to fall.
    double max_speed = 0;
    for (const Vec3& v : first.velocity) max_speed = std::max(max_speed, double(norm(v)));
    CHECK(max_speed > 0.1);
    create_openmp_simulation(setup, 0);  // restore the default thread count
}

namespace {
void compare_cuda_with_openmp(SimulationParams::Lists lists) {
    if (!cuda_backend_info().available) {
        MESSAGE("skipped: " << cuda_backend_info().description);
        return;
    }
    SimulationSetup setup = small_dam_break();
    setup.params.neighbor_lists = lists;  // the same neighbour structure on both sides
    const HostParticles cpu = run(create_openmp_simulation(setup, 0), 50);
    const HostParticles gpu = run(create_cuda_simulation(setup), 50);
    REQUIRE(cpu.position.size() == gpu.position.size());
    const double domain_size = norm(setup.params.domain_max - setup.params.domain_min);
    double worst = 0;
    for (std::size_t i = 0; i < cpu.position.size(); ++i) worst = std::max(worst, double(norm(cpu.position[i] - gpu.position[i])));
    MESSAGE("largest position difference after 50 steps: " << worst << " m (" << worst / domain_size << " of the domain)");
    CHECK(worst < 1e-4 * domain_size);
    // And the run did something: a comparison of two resting columns would prove little.
    double max_speed = 0;
    for (const Vec3& v : gpu.velocity) max_speed = std::max(max_speed, double(norm(v)));
    CHECK(max_speed > 0.1);
}
}  // namespace

TEST_CASE("CUDA and OpenMP agree on a 10k-particle dam break, grid gathers") {
    compare_cuda_with_openmp(SimulationParams::Lists::kOff);
}

TEST_CASE("CUDA and OpenMP agree on a 10k-particle dam break, neighbour lists") {
    compare_cuda_with_openmp(SimulationParams::Lists::kOn);
}

// Lists hold the pairs within h at the start of a step; grid gathers also see pairs that come
// within h while PCISPH predicts (weights of order (Δt |v_ij| / h)³), so the two differ by rounding-
// sized amounts that grow slowly, not bitwise.
TEST_CASE("neighbour lists and grid gathers give the same dam break") {
    SimulationSetup setup = small_dam_break();
    setup.params.neighbor_lists = SimulationParams::Lists::kOn;
    const HostParticles with_lists = run(create_openmp_simulation(setup, 0), 50);
    setup.params.neighbor_lists = SimulationParams::Lists::kOff;
    const HostParticles with_grid = run(create_openmp_simulation(setup, 0), 50);
    double worst = 0;
    for (std::size_t i = 0; i < with_lists.position.size(); ++i)
        worst = std::max(worst, double(norm(with_lists.position[i] - with_grid.position[i])));
    MESSAGE("largest position difference, lists against grid, after 50 steps: " << worst << " m");
    CHECK(worst < 1e-3 * setup.params.fluid.spacing);
}

TEST_CASE("solver.eta_max bounds the peak density error of every step") {
    SimulationSetup setup = small_dam_break();
    auto free_run = create_openmp_simulation(setup, 0);
    setup.params.solver.eta_max = Real(0.005);
    auto bounded_run = create_openmp_simulation(setup, 0);
    long free_iterations = 0, bounded_iterations = 0;
    double free_peak = 0;
    for (int s = 0; s < 60; ++s) {
        free_run->step();
        bounded_run->step();
        free_iterations += free_run->last_report().iterations;
        free_peak = std::max(free_peak, free_run->last_report().density_error_max);
        const StepReport& r = bounded_run->last_report();
        bounded_iterations += r.iterations;
        if (r.iterations < setup.params.solver.max_iterations) CHECK(r.density_error_max <= 0.005);
    }
    MESSAGE("peak error without eta_max " << 100 * free_peak << "%; iterations " << free_iterations << " without, "
                                          << bounded_iterations << " with eta_max 0.5%");
    CHECK(free_peak > 0.005);                         // the bound had something to do
    CHECK(bounded_iterations > free_iterations);      // and it cost iterations
}
