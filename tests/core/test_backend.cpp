// The OpenMP backend's primitives against plain sequential answers (the same checks run on the
// CUDA backend in tests/cuda_backend), and its memory ledger.
#include <doctest/doctest.h>

#include "backend/backend.hpp"
#include "backend_primitives.hpp"

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
