// Whether this test program was built with AddressSanitizer (`make sanitize`), and with it the
// meltwater it runs: ASan reserves terabytes of address space for its shadow memory, so a child
// run under `ulimit -v` cannot start, and memory is bounded by ASan's own RSS limit instead.
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define MW_TEST_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MW_TEST_UNDER_ASAN 1
#endif
#endif
#ifndef MW_TEST_UNDER_ASAN
#define MW_TEST_UNDER_ASAN 0
#endif

namespace mw_test {

// A shell prefix that bounds a child's memory (about 4 GB) and time (30 s), so that a regression
// that hangs or eats memory fails its test instead of stalling the suite or the machine.
inline const char* memory_and_time_guard() {
    return MW_TEST_UNDER_ASAN ? "export ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}hard_rss_limit_mb=4000\"; timeout 30"
                              : "ulimit -v 4000000; timeout 30";
}

}  // namespace mw_test
