// The OpenMP backend's primitives against plain sequential answers (the same checks run on the
// CUDA backend in tests/cuda_backend), and what a device context keeps to itself.
#include <doctest/doctest.h>

#include <cstring>

#include "backend/backend.hpp"
#include "backend_primitives.hpp"
#include "test_setups.hpp"

using namespace mw;

TEST_CASE("reductions, scan, sort and atomics agree with sequential answers") {
    const DeviceContext device;
    test::check_reductions(device);
    test::check_exclusive_scan(device);
    test::check_sort_pairs(device);
    test::check_atomics(device);
}

TEST_CASE("struct reductions, a scan and a reduction back to back, and stage timers") {
    const DeviceContext device;
    test::check_struct_reductions(device);
    test::check_scan_then_reduce(device);
    test::check_stage_timers(device);
}

TEST_CASE("a device context's scratch is its own") {
    const DeviceContext device;
    test::check_context_scratch(device);
}

// Each simulation owns its device context: its memory figure is its own whatever else the
// process runs, and two simulations stepped in turn take the steps each takes alone.
TEST_CASE("two simulations in one process share no state") {
    const SimulationSetup small =
        test::fluid_in_box({0, 0, 0}, {0.3f, 0.3f, 0.3f}, {0, 0, 0}, {0.1f, 0.1f, 0.1f}, 0.02f, 0.001f);
    const SimulationSetup large =
        test::fluid_in_box({0, 0, 0}, {0.6f, 0.6f, 0.6f}, {0, 0, 0}, {0.4f, 0.4f, 0.4f}, 0.02f, 0.001f);
    auto alone = create_openmp_simulation(small, 0);
    for (int k = 0; k < 5; ++k) alone->step();
    const std::size_t small_bytes = alone->device_bytes();
    HostParticles alone_particles;
    alone->download(alone_particles);

    auto first = create_openmp_simulation(large, 0);
    auto second = create_openmp_simulation(small, 0);
    for (int k = 0; k < 5; ++k) {
        first->step();
        second->step();
    }
    CHECK(second->device_bytes() == small_bytes);
    CHECK(first->device_bytes() > small_bytes);
    HostParticles paired;
    second->download(paired);
    CHECK(paired.position.size() == alone_particles.position.size());
    CHECK(std::memcmp(paired.position.data(), alone_particles.position.data(),
                      paired.position.size() * sizeof(Vec3)) == 0);
}
