#!/usr/bin/env bash
# The sanitizer build (`make sanitize`, `make fuzz`): clang with AddressSanitizer and
# UndefinedBehaviorSanitizer, libFuzzer's coverage in every library, the CUDA backend left out,
# in build-sanitize/ (SANITIZE_BUILD_DIR). Installs what is missing, configures once, then builds
# the targets named (all when none).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh --packages-only
# clang and its runtimes (ASan, UBSan, libFuzzer) and its OpenMP.
./scripts/install_packages.sh clang libclang-rt-14-dev libomp-dev

build_dir=${SANITIZE_BUILD_DIR:-build-sanitize}
if [[ ! -f "$build_dir/CMakeCache.txt" ]]; then
  # -O1 keeps the sanitizers' reports readable and the suite's time within reach.
  CC=clang CXX=clang++ cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DMELTWATER_CUDA=OFF -DMELTWATER_SANITIZE=ON -DMELTWATER_FUZZ=ON >/dev/null
  echo "setup: configured $build_dir (clang, ASan + UBSan, libFuzzer, no CUDA)"
fi
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build "$build_dir" -j "${JOBS:-$(nproc)}" "${targets[@]}"
