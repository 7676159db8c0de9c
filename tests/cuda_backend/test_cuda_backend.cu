// The CUDA backend's primitives against plain sequential answers: the checks of
// tests/core/backend_primitives.hpp compiled for the GPU. Built only with the CUDA backend; each
// case skips with a message where no CUDA device is present (CI).
#define DOCTEST_CONFIG_IMPLEMENT
#include <string>

#include "tests/skip.hpp"

#define MW_BACKEND_CUDA
#include "../core/backend_primitives.hpp"

namespace {
bool gpu_present() {
    if (mw::backend_available()) return true;
    MW_SKIP("no usable CUDA device (" << mw::unavailable_reason() << ")");
    return false;
}
// A context per case, made only where a GPU is present.
#define MW_WITH_DEVICE(check)            \
    if (gpu_present()) {                 \
        const mw::DeviceContext device;  \
        mw::test::check(device);         \
    }
}  // namespace

TEST_CASE("CUDA reductions agree with sequential answers") {
    MW_WITH_DEVICE(check_reductions)
}
TEST_CASE("CUDA exclusive scan agrees with a sequential scan, also in place") {
    MW_WITH_DEVICE(check_exclusive_scan)
}
TEST_CASE("CUDA radix sort is a stable sort") {
    MW_WITH_DEVICE(check_sort_pairs)
}
TEST_CASE("CUDA atomics lose no update") {
    MW_WITH_DEVICE(check_atomics)
}
TEST_CASE("CUDA: a device context's scratch is its own") {
    MW_WITH_DEVICE(check_context_scratch)
}
TEST_CASE("CUDA struct reductions, at every size from empty to many blocks") {
    MW_WITH_DEVICE(check_struct_reductions)
}
TEST_CASE("CUDA scan and reduction back to back (one pinned result buffer)") {
    MW_WITH_DEVICE(check_scan_then_reduce)
}
TEST_CASE("CUDA stage timers (events)") {
    MW_WITH_DEVICE(check_stage_timers)
}
// An allocation larger than the device is a DeviceError that says so (the command line adds the
// scene's estimate to it), and leaves the device usable.
TEST_CASE("CUDA out of memory is a clear error, and the device stays usable") {
    if (!gpu_present()) return;
    const auto free_bytes = static_cast<std::size_t>(mw::device_memory_free());
    std::string message;
    try {
        mw::DeviceArray<char> too_large(2 * free_bytes + (std::size_t(1) << 30));
    } catch (const mw::DeviceError& e) {
        message = e.what();
    }
    CHECK(message.find("out of GPU memory") != std::string::npos);
    const mw::DeviceContext device;
    mw::test::check_reductions(device);
}

MW_TEST_MAIN
