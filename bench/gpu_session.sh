#!/usr/bin/env bash
# One call for a GPU machine (issue 5): build for sm_90, run every test (the CUDA cross-backend
# tests run in full there), compute-sanitizer memcheck and racecheck on a small dam break, the
# benchmarks, and an ncu profile of the heaviest kernels. Writes everything under $OUT (or
# results/gpu/) so a machine that keeps nothing can hand it back.
# Not yet run on a GPU: written while no GPU was available (see bench/results/).
set -uo pipefail
cd "$(dirname "$0")/.."
out=${OUT:-results/gpu}
mkdir -p "$out"
build=build-gpu
log() { echo "== $*" | tee -a "$out/session.log"; }

log "build (sm_90, Release)"
cmake -S . -B $build -G Ninja -DCMAKE_BUILD_TYPE=Release -DMELTWATER_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 \
  >"$out/configure.log" 2>&1 && cmake --build $build -j "$(nproc)" >"$out/build.log" 2>&1 || { log "build failed"; tail -30 "$out/build.log"; exit 1; }
nvidia-smi >"$out/nvidia-smi.txt" 2>&1
$build/meltwater backends | tee -a "$out/session.log"

log "tests"
(cd $build && ctest --output-on-failure -j 8) >"$out/ctest.log" 2>&1; tail -5 "$out/ctest.log" | tee -a "$out/session.log"

log "compute-sanitizer on a small dam break"
for tool in memcheck racecheck; do
  compute-sanitizer --tool $tool --error-exitcode 9 $build/meltwater run scenes/hydrostatic_column.json \
    --backend cuda --steps 5 --out /tmp/mw-sanitize --quiet >"$out/sanitizer-$tool.log" 2>&1
  log "$tool exit $? ($(grep -c 'ERROR SUMMARY: 0' "$out/sanitizer-$tool.log") clean summaries)"
done

log "benchmarks"
BENCH_THREADS=$(nproc) bench/run_benchmarks.sh $build >"$out/bench.log" 2>&1; tail -3 "$out/bench.log" | tee -a "$out/session.log"
cp bench/results/*"$(date +%Y-%m-%d)"* "$out/" 2>/dev/null

log "ncu: the three heaviest kernels of a 1M-particle dam break step"
ncu --target-processes all --launch-skip 40 --launch-count 30 --set basic \
  $build/bench_fluid --backend cuda --quick >"$out/ncu.txt" 2>&1 || log "ncu failed (see ncu.txt)"
log "done; results in $out"
