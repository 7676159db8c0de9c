// Skipping a test case that cannot run here (no GPU, no shared meshes, no meshio):
//
//     if (!cuda_backend_info().available) { MW_SKIP("no CUDA device"); return; }
//
// The case says why, and the test program's main (MW_TEST_MAIN) then exits with kSkipExitCode
// when it runs under ctest, which counts that exit code as skipped (SKIP_RETURN_CODE in
// CMakeLists.txt). Only when every check passed: a case that failed a check, before or after
// skipping, still exits 1 and fails. (ctest's SKIP_REGULAR_EXPRESSION, used before, outranks the
// exit code and a failure pattern alike, so a failing case that printed "SKIPPED" passed as
// skipped.) Run directly, outside ctest, a program that skipped exits 0.
#pragma once
#include <cstdlib>

#include <doctest/doctest.h>

namespace mw_test {

constexpr int kSkipExitCode = 77;

inline bool& skip_recorded() {
    static bool skipped = false;
    return skipped;
}

inline int run_tests(int argc, char** argv) {
    doctest::Context context(argc, argv);
    const int result = context.run();
    if (context.shouldExit()) return result;  // --help, --list-test-cases and the like
    // ctest sets MW_TEST_UNDER_CTEST (CMakeLists.txt) so that a direct run reads as doctest's.
    const bool under_ctest = std::getenv("MW_TEST_UNDER_CTEST") != nullptr;
    return result == 0 && skip_recorded() && under_ctest ? kSkipExitCode : result;
}

}  // namespace mw_test

#define MW_SKIP(why)                               \
    do {                                           \
        MESSAGE("SKIPPED: " << why);               \
        ::mw_test::skip_recorded() = true;         \
    } while (false)

// The main of a test program: one translation unit per program defines it.
#define MW_TEST_MAIN \
    int main(int argc, char** argv) { return ::mw_test::run_tests(argc, argv); }
