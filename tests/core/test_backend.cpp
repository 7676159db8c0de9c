// The OpenMP backend's primitives against plain sequential answers (the same checks run on the
// CUDA backend in tests/cuda_backend), its memory ledger, and the lifetime of its shared scratch.
#include <doctest/doctest.h>

#include "backend/backend.hpp"
#include "backend_primitives.hpp"
#include "test_setups.hpp"

using namespace mw;

TEST_CASE("reductions, scan, sort and atomics agree with sequential answers") {
    test::check_reductions();
    test::check_exclusive_scan();
    test::check_sort_pairs();
    test::check_atomics();
}

TEST_CASE("struct reductions, a scan and a reduction back to back, and stage timers") {
    test::check_struct_reductions();
    test::check_scan_then_reduce();
    test::check_stage_timers();
}

TEST_CASE("memory ledger follows allocations") { test::check_memory_ledger(); }

// The sort's scratch is shared by the simulations of a process and freed with the last of them,
// so that a simulation's device_bytes() is its own, not the largest of the process so far.
TEST_CASE("the backend's shared scratch lives as long as its last simulation") {
    const SimulationSetup small =
        test::fluid_in_box({0, 0, 0}, {0.3f, 0.3f, 0.3f}, {0, 0, 0}, {0.1f, 0.1f, 0.1f}, 0.02f, 0.001f);
    const SimulationSetup large =
        test::fluid_in_box({0, 0, 0}, {0.6f, 0.6f, 0.6f}, {0, 0, 0}, {0.4f, 0.4f, 0.4f}, 0.02f, 0.001f);
    auto first = create_openmp_simulation(large, 0);
    first->step();
    const std::size_t large_scratch = backend_scratch_bytes();
    CHECK(large_scratch > 0);
    {
        auto second = create_openmp_simulation(small, 0);
        second->step();
        CHECK(backend_scratch_bytes() == large_scratch);  // shared, and still the large one's
    }
    CHECK(backend_scratch_bytes() == large_scratch);  // the first still uses it
    first.reset();
    CHECK(backend_scratch_bytes() == 0);
    auto alone = create_openmp_simulation(small, 0);
    alone->step();
    CHECK(backend_scratch_bytes() > 0);
    CHECK(backend_scratch_bytes() < large_scratch);  // sized for the small one alone
}
