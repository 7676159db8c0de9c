#!/usr/bin/env bash
# `make sanitize`: the whole test suite (or the ctest selection given, e.g. -L '^cli$') built
# with AddressSanitizer and UndefinedBehaviorSanitizer; SANITIZE_TARGETS, when set, names the only
# programs to build (the selection must need no other). Any report fails its test: ASan aborts,
# UBSan stops at the first undefined behaviour, LeakSanitizer fails a program that leaks.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck disable=SC2086
./scripts/sanitize_build.sh ${SANITIZE_TARGETS:-}
build_dir=${SANITIZE_BUILD_DIR:-build-sanitize}
suppressions=$PWD/scripts/sanitizer_suppressions
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1"
export LSAN_OPTIONS="suppressions=$suppressions/leaks.txt"
# LeakSanitizer stops the program's threads with ptrace; where the machine forbids that (some
# containers), leaks go unchecked and the rest runs as before.
if "$build_dir/meltwater" --version 2>&1 | grep -q "LeakSanitizer has encountered a fatal error"; then
  echo "sanitize: LeakSanitizer cannot run here (ptrace is not allowed); leaks are not checked"
  export ASAN_OPTIONS="abort_on_error=1:detect_leaks=0"
fi
start=$(date +%s)
cd "$build_dir"
status=0
ctest --output-on-failure -j "${JOBS:-$(nproc)}" "$@" || status=$?
echo "sanitize: the tests took $(( $(date +%s) - start )) s under ASan + UBSan"
exit $status
