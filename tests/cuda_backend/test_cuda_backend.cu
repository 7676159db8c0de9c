// The CUDA backend's primitives against plain sequential answers: the checks of
// tests/core/backend_primitives.hpp compiled for the GPU. Built only with the CUDA backend; each
// case skips with a message where no CUDA device is present (CI).
#define DOCTEST_CONFIG_IMPLEMENT
#include "tests/skip.hpp"

#define MW_BACKEND_CUDA
#include "../core/backend_primitives.hpp"

namespace {
bool gpu_present() {
    if (mw::backend_available()) return true;
    MW_SKIP("no usable CUDA device (" << mw::unavailable_reason() << ")");
    return false;
}
}  // namespace

TEST_CASE("CUDA reductions agree with sequential answers") {
    if (gpu_present()) mw::test::check_reductions();
}
TEST_CASE("CUDA exclusive scan agrees with a sequential scan, also in place") {
    if (gpu_present()) mw::test::check_exclusive_scan();
}
TEST_CASE("CUDA radix sort is a stable sort") {
    if (gpu_present()) mw::test::check_sort_pairs();
}
TEST_CASE("CUDA atomics lose no update") {
    if (gpu_present()) mw::test::check_atomics();
}
TEST_CASE("CUDA memory ledger follows allocations") {
    if (gpu_present()) mw::test::check_memory_ledger();
}

MW_TEST_MAIN
