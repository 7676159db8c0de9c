#!/usr/bin/env bash
# `make bench`: runs every benchmark on every backend available and writes one report,
# bench/results/DATE-DEVICE.md, with the date, the device and the commands that produced it.
# Usage: bench/run_benchmarks.sh [BUILD_DIR] [extra bench_fluid options, e.g. --quick or --large]
# BENCH_THREADS=N: OpenMP threads (default: all cores). BENCH_BACKENDS: the fluid blocks to run,
# "openmp cuda" by default (CUDA only where a GPU is usable); BENCH_BACKENDS=cuda skips the OpenMP
# fluid block (a GPU session, bench/gpu_session.sh) and fails when no GPU is usable.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
threads=${BENCH_THREADS:-$(nproc)}
backends=${BENCH_BACKENDS:-openmp cuda}
want() { [[ " $backends " == *" $1 "* ]]; }
date=$(date +%Y-%m-%d)
gpu=$("$build/meltwater" backends --json 2>/dev/null | python3 -c 'import json,sys; b=json.load(sys.stdin); c=[x for x in b["backends"] if x["name"]=="cuda"]; print("cuda" if c and c[0]["available"] else "")' 2>/dev/null || true)
if [[ -n "$gpu" ]]; then
  device=$(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | head -1 | tr ' ' '-' | tr -cd 'A-Za-z0-9-')
else
  device="cpu-${threads}threads"
fi
if [[ -n "${BENCH_BACKENDS:-}" ]] && want cuda && [[ -z "$gpu" ]]; then
  echo "bench: BENCH_BACKENDS=$BENCH_BACKENDS but no usable CUDA device in $build" >&2
  exit 3
fi
# A second report of the same day and device does not overwrite the first: -run2, -run3, ...
out="bench/results/${date}-${device}.md"
n=2
while [[ -e $out ]]; do out="bench/results/${date}-${device}-run$((n++)).md"; done
mkdir -p bench/results
{
  echo "# Benchmarks, ${date}, ${device}"
  echo
  echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')"
  echo "Command: \`make bench\` (bench/run_benchmarks.sh $build $*), BENCH_THREADS=${threads}${BENCH_BACKENDS:+, BENCH_BACKENDS=$BENCH_BACKENDS}"
  echo
} > "$out"
if want openmp; then
  echo "## Fluid, OpenMP (${threads} threads)" >> "$out"
  "$build/bench_fluid" --backend openmp --threads "$threads" --out "$out" "$@"
fi
if [[ -n "$gpu" ]] && want cuda; then
  echo "## Fluid, CUDA" >> "$out"
  "$build/bench_fluid" --backend cuda --large --out "$out" "$@"
fi
# bench_lsm times every backend available, also in a GPU session: its OpenMP rows on that
# machine's cores stand beside the CUDA rows of the same run (a few seconds in all).
if [[ -x "$build/bench_lsm" ]]; then
  echo "## LSM (elastic cubes, w = 2, and rigid cubes; every backend available)" >> "$out"
  OMP_NUM_THREADS=$threads "$build/bench_lsm" >> "$out" || echo "bench_lsm failed" >> "$out"
fi
# Sampling runs on the host only: a GPU session (BENCH_BACKENDS without openmp) leaves it to the
# development machine's reports.
if [[ -x "$build/bench_sampling" ]] && want openmp; then
  echo "## Sampling (bunny, 0.5 m)" >> "$out"
  "$build/bench_sampling" --threads "$threads" --out "$out.sampling.tmp" && cat "$out.sampling.tmp" >> "$out" && rm -f "$out.sampling.tmp"
fi
echo "bench: report written to $out"
