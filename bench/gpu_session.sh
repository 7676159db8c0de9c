#!/usr/bin/env bash
# A GPU session in stages, for a GPU machine lent through the `run` tool: 16 cores, nvcc,
# ncu and compute-sanitizer, but none of this project's Debian packages and no network, so NOTHING
# is built there. Here, first: `bench/gpu_bundle.sh` builds build-gpu and packs it (executables,
# shared libraries, meshes) into gpu-bundle/meltwater-gpu.tar.xz. Then one or two run calls, each
# `timeout_s: 600` and `carry: ["gpu-bundle"]` (bench/README.md), within a session's 15 minutes of
# device time (the machine's start counts too):
#   1. bash bench/gpu_session.sh unpack test bench   the CUDA tests, then the benchmark (targets)
#   2. bash bench/gpu_session.sh sanitize ncu        at once, while the machine is warm, if the
#                                                    device tool's status has 6 minutes left
# Usage: bench/gpu_session.sh STAGE...   stages, in the order given:
#   unpack    unpack the bundle into build-gpu/, check the libraries (ldd), nvidia-smi,
#             `meltwater backends`, and a 20-step dam break on CUDA (MELTWATER_CUDA_SYNC=1)
#   test      the CUDA cases and test_cli with MELTWATER_CUDA_SYNC=1, the CUDA cases again without
#             it; each program's doctest summary. The CPU cases (which CI runs) only with
#             GPU_CPU_TESTS=1, while time remains
#   sanitize  compute-sanitizer memcheck and initcheck (skipped under gVisor, kernel 4.4.0, where
#             the tool refuses the device): hydrostatic column (grid gathers; then
#             neighbour lists and viscosity), the cantilever (solids), the cantilever in a pool
#             (fluid and a moving solid, viscosity, linear cell order), test_cuda_backend
#   bench     bench/run_benchmarks.sh build-gpu --large: the fluid benchmark on CUDA only
#             (BENCH_BACKENDS=cuda; dam breaks first, each section written as it finishes), then
#             bench_lsm (every backend); the host-only sampling benchmark is left out.
#             BENCH_SECTIONS=dams,paper,... picks bench_fluid's sections (all by default);
#             BENCH_BUDGET_S caps the stage (default 540 s) to leave time for a later stage
#   ncu       a 1M-particle dam break, 3 steps: every kernel's time, then `--set basic` on the
#             five kernels that take the most time (skipped under gVisor, where ncu cannot read
#             the counters)
# Every stage unpacks the bundle first if that is not done (a fresh machine, every call). Each
# writes its files under $GPU_WORK/STAGE (default /tmp/meltwater-gpu) and ends by packing them into
# $OUT/gpu-STAGE.tar.gz, with a short plain-text summary $OUT/gpu-STAGE.log (results/gpu/ when OUT
# is unset): two files a stage, so one call may run up to four stages within the run tool's 8 files.
# All stages of one call share a deadline (GPU_DEADLINE_S, default 540 s, under the tool's 600 s
# limit; set it lower when the tool's limit_s is lower): every command gets a timeout that leaves
# time to pack. Exit status: 0 when every check
# passed, 1 otherwise (the summaries say which).
#
# Paths baked into the executables: CMake compiled in MW_SOURCE_DIR (the repository root where the
# bundle was built, e.g. /work/main, recorded in build-gpu/BUNDLE_INFO), MW_BINARY
# (SOURCE_DIR/build-gpu/meltwater, which the CLI tests run) and MW_SHARED_DIR (SOURCE_DIR/../shared,
# where the meshes are read). Where the repository root here is elsewhere, SOURCE_DIR is made a
# symbolic link to it (commands run as root there), and MW_BINARY resolves because the bundle is
# unpacked into build-gpu/ at the root. SOURCE_DIR/../shared then resolves through the link: to
# the PARENT of this repository's root, plus /shared (the kernel follows the link before '..').
# The run tool does not carry the ../shared beside a checkout, so where that folder is absent it is
# made a link to build-gpu/bundle-shared (the meshes gpu_bundle.sh packed); if neither exists, the
# tests that need meshes skip with a message.
set -uo pipefail
cd "$(dirname "$0")/.." || exit 2
root=$(pwd -P)
# nvcc and compute-sanitizer under /usr/local/cuda; Nsight Compute in its own folder on some images.
export PATH="$PATH:/usr/local/cuda/bin$(for d in /opt/nvidia/nsight-compute/*/; do [[ -x ${d}ncu ]] && printf ':%s' "${d%/}"; done)"
build="build-gpu"
bundle="gpu-bundle/meltwater-gpu.tar.xz"
out=${OUT:-results/gpu}
mkdir -p "$out" && out=$(cd "$out" && pwd -P)
work_root=${GPU_WORK:-/tmp/meltwater-gpu}
mkdir -p "$work_root" && work_root=$(cd "$work_root" && pwd -P)
deadline=$((SECONDS + ${GPU_DEADLINE_S:-540}))
failed=0
bundle_ready=""
gpu=""

[[ $# -gt 0 ]] || { sed -n '2,33p' "$0"; exit 2; }
for s in "$@"; do
  case "$s" in unpack | test | sanitize | bench | ncu) ;; *) echo "gpu_session: unknown stage '$s'" >&2; exit 2 ;; esac
done

# ---- helpers ------------------------------------------------------------------------------------
# say: a line for the stage's summary (and its full log); log: the full log only.
say() { echo "$*" | tee -a "$summary" "$work/stage.log"; }
log() { echo "$*" >>"$work/stage.log"; }
fail() { failed=1; say "FAIL: $*"; }
# Seconds a command may take: at most $1, and never past the deadline less 30 s for packing.
budget() {
  local cap=$1 left=$((deadline - SECONDS - 30))
  ((left < cap)) && cap=$left
  ((cap < 5)) && cap=5
  echo "$cap"
}
time_left() { echo $((deadline - SECONDS)); }
# run_logged FILE SECONDS CMD...: runs CMD with a timeout, output to FILE; returns its status.
run_logged() {
  local file=$1 t=$2
  shift 2
  echo "\$ $*" >"$file"
  timeout --kill-after=10 "$t" "$@" >>"$file" 2>&1
  local rc=$?
  ((rc == 124 || rc == 137)) && echo "gpu_session: timed out after ${t} s" >>"$file"
  return $rc
}

begin_stage() {
  stage=$1
  work=$work_root/$stage
  rm -rf "$work" && mkdir -p "$work"
  summary=$out/gpu-$stage.log
  : >"$summary"
  stage_start=$SECONDS
  say "== gpu_session $stage: $(date -u +%Y-%m-%dT%H:%M:%SZ) on $(hostname), $(nproc) cores, $(time_left) s left"
}

end_stage() {
  say "== $stage done in $((SECONDS - stage_start)) s"
  cp "$summary" "$work/summary.log"
  local tarball=$out/gpu-$stage.tar.gz
  tar -C "$work_root" -czf "$tarball" "$stage"
  # The run tool returns files of at most 16 MiB: leave the largest files out if needed.
  if (($(stat -c %s "$tarball") > 15 * 1048576)); then
    local big
    big=$(find "$work" -type f -size +1M -printf '%P\n')
    tar -C "$work_root" -czf "$tarball" --exclude-from=<(sed "s|^|$stage/|" <<<"$big") "$stage"
    say "left out of the archive (over 1 MiB each): $(echo $big)"
  fi
}

# ---- the bundle ---------------------------------------------------------------------------------
# Unpacks gpu-bundle/ into build-gpu/ once (a stamp records which archive), links the baked-in
# source directory and ../shared, and sets LD_LIBRARY_PATH (the fallback libstdc++ only if needed).
# A build-gpu/ configured here by CMake (the development machine) is used as it is.
ensure_bundle() {
  [[ -n "$bundle_ready" ]] && return 0
  local source_dir stamp=""
  if [[ -f $build/CMakeCache.txt ]]; then
    source_dir=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' $build/CMakeCache.txt)
    log "build-gpu/ is a CMake build directory: using it as it is (source $source_dir)"
  else
    [[ -f $bundle ]] || { fail "no $bundle: run bench/gpu_bundle.sh on the development machine and carry gpu-bundle"; return 1; }
    stamp=$(stat -c '%s %Y' "$bundle")
    if [[ "$(cat $build/.bundle-stamp 2>/dev/null)" != "$stamp" ]]; then
      mkdir -p $build
      # tar needs the xz program for .tar.xz, which some images lack; Python's lzma does not.
      if ! tar -C $build -xJf "$bundle" 2>>"$work/stage.log"; then
        log "tar -xJf failed; unpacking with python3's tarfile"
        python3 -c 'import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])' "$bundle" "$build" ||
          { fail "could not unpack $bundle"; return 1; }
      fi
      echo "$stamp" >$build/.bundle-stamp
      log "unpacked $bundle ($(du -sh $build | cut -f1)) into $build/"
    else
      log "$bundle already unpacked"
    fi
    source_dir=$(sed -n 's/^source_dir=//p' $build/BUNDLE_INFO)
    # Libraries: the bundle's; libstdc++/libgcc_s from the fallback folder only if the system's fail.
    local libs=$root/$build/bundle-lib missing
    missing=$(for f in $build/meltwater $build/test_* $build/bench_*; do LD_LIBRARY_PATH=$libs ldd "$f" 2>&1; done | grep 'not found' | sort -u)
    if [[ -n "$missing" ]]; then
      log "with the system's libstdc++/libgcc_s: $missing"
      libs=$libs:$root/$build/bundle-lib-fallback
      missing=$(for f in $build/meltwater $build/test_* $build/bench_*; do LD_LIBRARY_PATH=$libs ldd "$f" 2>&1; done | grep 'not found' | sort -u)
      log "using the bundle's fallback libstdc++/libgcc_s"
    fi
    [[ -z "$missing" ]] || { fail "libraries not found: $missing"; return 1; }
    export LD_LIBRARY_PATH=$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  fi
  # The baked-in source directory must lead here (MW_BINARY, MW_SOURCE_DIR).
  if [[ -n "$source_dir" && "$(readlink -f "$source_dir" 2>/dev/null)" != "$root" ]]; then
    if [[ -L "$source_dir" || ! -e "$source_dir" ]]; then
      mkdir -p "$(dirname "$source_dir")" && ln -sfn "$root" "$source_dir" &&
        log "linked $source_dir -> $root" || say "WARNING: could not link $source_dir -> $root (CLI tests will fail)"
    else
      say "WARNING: $source_dir exists and is not this repository: the tests that run it by path will fail"
    fi
  fi
  # Meshes: SOURCE_DIR/../shared, which resolves to the parent of this root (see the header).
  local shared
  shared=$(dirname "$root")/shared
  if [[ ! -d "$shared/assets/meshes" ]]; then
    if [[ -d $build/bundle-shared/assets && ! -e "$shared" ]] || [[ -L "$shared" ]]; then
      ln -sfn "$root/$build/bundle-shared" "$shared" && log "linked $shared -> $root/$build/bundle-shared"
    fi
    [[ -d "$shared/assets/meshes" ]] || say "WARNING: no meshes at $shared/assets/meshes: mesh tests will skip"
  fi
  [[ -x $build/meltwater ]] || { fail "no $build/meltwater"; return 1; }
  bundle_ready=1
  # Is there a usable GPU? (the CUDA backend compiled in and a device found)
  if $build/meltwater backends --json 2>/dev/null | python3 -c 'import json,sys; b=json.load(sys.stdin); sys.exit(0 if any(x["name"]=="cuda" and x["available"] for x in b["backends"]) else 1)' 2>/dev/null; then
    gpu=1
  else
    gpu=""
  fi
  return 0
}

# A stage that needs the GPU says so and stops when there is none.
need_gpu() {
  [[ -n "$gpu" ]] && return 0
  say "skipped: no usable CUDA device ($($build/meltwater backends 2>&1 | grep -i cuda | head -1))"
  return 1
}
# compute-sanitizer and ncu do not work under gVisor (kernel 4.4.0: the sanitizer refuses the
# device, ncu cannot load its profiler library; the device tool's KINDS.md): a stage
# that needs them says so instead of failing ten times.
need_profilers() {
  [[ "$(uname -r)" != 4.4.0* ]] && return 0
  say "skipped: kernel $(uname -r) is gVisor's, where compute-sanitizer and ncu do not work"
  return 1
}

# ---- stages -------------------------------------------------------------------------------------
stage_unpack() {
  ensure_bundle || return
  cat $build/BUNDLE_INFO >"$work/BUNDLE_INFO" 2>/dev/null && say "bundle: $(tr '\n' ' ' <"$work/BUNDLE_INFO")"
  say "glibc here: $(ldd --version 2>&1 | head -1); kernel $(uname -r)"
  say "LD_LIBRARY_PATH=${LD_LIBRARY_PATH:-}"
  for f in $build/meltwater $build/test_* $build/bench_*; do
    echo "# $f"
    ldd "$f" 2>&1
  done >"$work/ldd.txt"
  say "ldd meltwater: $(ldd $build/meltwater | awk '$2 == "=>" {print $1 "=" $3}' | grep -E 'embree|tbb|tinyobj|gomp|stdc|gcc_s' | tr '\n' ' ')"
  if grep -q 'not found' "$work/ldd.txt"; then fail "ldd: $(grep 'not found' "$work/ldd.txt" | sort -u | head -5)"; fi
  for t in nvidia-smi nvcc ncu compute-sanitizer python3; do say "$t: $(command -v $t || echo missing)"; done
  if command -v nvidia-smi >/dev/null; then
    nvidia-smi >"$work/nvidia-smi.txt" 2>&1
    say "gpu: $(nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv,noheader 2>&1 | head -1)"
  fi
  $build/meltwater backends >"$work/backends.txt" 2>&1 || fail "meltwater backends exit $?"
  cat "$work/backends.txt" >>"$summary"
  need_gpu || return
  local smoke=/tmp/meltwater-gpu-smoke
  for backend in cuda openmp; do
    rm -rf $smoke-$backend
    MELTWATER_CUDA_SYNC=1 run_logged "$work/smoke-$backend.log" "$(budget 120)" \
      $build/meltwater run scenes/dam_break.json --backend $backend --steps 20 --out $smoke-$backend
    local rc=$?
    cp $smoke-$backend/summary.json "$work/smoke-$backend-summary.json" 2>/dev/null
    cp $smoke-$backend/stats.csv "$work/smoke-$backend-stats.csv" 2>/dev/null
    if ((rc == 0)); then say "smoke $backend (20 steps): $(tail -2 "$work/smoke-$backend.log" | tr '\n' ' ')"
    else fail "smoke $backend exit $rc: $(tail -3 "$work/smoke-$backend.log" | tr '\n' ' ')"; fi
  done
}

# One test program: PASS/FAIL line with its doctest summary and the skip messages.
run_test_program() {
  local name=$1 file=$2
  shift 2
  (cd $build && run_logged "$file" "$(budget 300)" ./"$name" "$@")
  local rc=$?
  local cases skips
  cases=$(grep '\[doctest\] test cases' "$file" | tail -1 | sed 's/\[doctest\] //')
  skips=$(grep -ci 'skipped:' "$file")
  if ((rc == 0)); then
    say "ok   $name${*:+ $*} | ${cases:-no doctest summary} | $skips skip messages"
  else
    fail "$name${*:+ $*} exit $rc | ${cases:-no doctest summary}"
    grep -E 'ERROR|FATAL|timed out|error while loading' "$file" | head -15 >>"$summary"
  fi
  ((skips > 0)) && grep -hi 'skipped:' "$file" | sort | uniq -c | head -5 | sed 's/^/       /' >>"$summary"
}

stage_test() {
  ensure_bundle || return
  [[ -n "$gpu" ]] || say "no usable CUDA device: the CUDA cases skip with a message"
  # What only this machine can check comes first, so that a short call still does it: the CUDA
  # cases, and the command line's tests (their runs pick CUDA here through --backend auto).
  say "-- pass 1, MELTWATER_CUDA_SYNC=1 (synchronise and check after every launch): the CUDA cases and test_cli"
  [[ -x $build/test_cuda_backend ]] && MELTWATER_CUDA_SYNC=1 run_test_program test_cuda_backend "$work/test_cuda_backend.log"
  MELTWATER_CUDA_SYNC=1 run_test_program test_core "$work/test_core-cuda.log" '-tc=*CUDA*'
  MELTWATER_CUDA_SYNC=1 run_test_program test_lsm "$work/test_lsm-cuda.log" '-tc=*CUDA*'
  MELTWATER_CUDA_SYNC=1 run_test_program test_cli "$work/test_cli.log"
  if [[ -n "$gpu" ]]; then
    if (($(time_left) < 120)); then say "pass 2 skipped: $(time_left) s left"; return; fi
    say "-- pass 2, the CUDA cases without MELTWATER_CUDA_SYNC"
    [[ -x $build/test_cuda_backend ]] && run_test_program test_cuda_backend "$work/test_cuda_backend-nosync.log"
    run_test_program test_core "$work/test_core-cuda-nosync.log" '-tc=*CUDA*'
    run_test_program test_lsm "$work/test_lsm-cuda-nosync.log" '-tc=*CUDA*'
  fi
  # The rest of the suite (CPU cases, which CI runs) only when asked: device time is scarce.
  if [[ -z "${GPU_CPU_TESTS:-}" ]]; then say "pass 3 (the CPU cases) not run: set GPU_CPU_TESTS=1 for it"; return; fi
  if (($(time_left) < 150)); then say "pass 3 (the CPU cases) skipped: $(time_left) s left"; return; fi
  say "-- pass 3, the other cases (OpenMP and the sampler)"
  local name
  for name in $(cat $build/tests.txt 2>/dev/null || (cd $build && ls test_*)); do
    case "$name" in
      test_cuda_backend | test_cli) ;;
      test_core | test_lsm) run_test_program "$name" "$work/$name-cpu.log" '-tce=*CUDA*' ;;
      *) run_test_program "$name" "$work/$name.log" ;;
    esac
  done
}

stage_sanitize() {
  ensure_bundle || return
  need_gpu || return
  need_profilers || return
  local tool name rc
  local -A cases=(
    [hydrostatic]="scenes/hydrostatic_column.json"
    [hydrostatic-lists-viscosity]="scenes/hydrostatic_column.json --set neighbors.lists=on --set fluid.viscosity=0.01"
    [cantilever]="scenes/cantilever.json"
    # Fluid around a moving solid (boundary volumes of moving solids, the solid group in every
    # gather), with viscosity and the linear cell order: paths the other cases leave out.
    [beam-in-pool]="scenes/cantilever.json --set boundary.walls=true --set fluid_blocks=[{\"min\":[0.3,0.45,0.05],\"max\":[0.9,0.85,0.35]}] --set fluid.viscosity=0.01 --set fluid.wall_viscosity=0.01 --set neighbors.ordering=linear"
  )
  for tool in memcheck initcheck; do
    for name in hydrostatic hydrostatic-lists-viscosity cantilever beam-in-pool; do
      rm -rf /tmp/meltwater-gpu-san
      # Split on spaces only: the JSON of beam-in-pool must not be read as a glob pattern.
      local -a scene_args
      read -ra scene_args <<<"${cases[$name]}"
      run_logged "$work/$tool-$name.log" "$(budget 150)" compute-sanitizer --tool $tool --error-exitcode 9 \
        --print-limit 30 $build/meltwater run "${scene_args[@]}" --backend cuda --steps 5 \
        --set 'output.formats=[]' --out /tmp/meltwater-gpu-san --quiet
      rc=$?
      local errs
      errs=$(grep -E '(ERROR|LEAK) SUMMARY' "$work/$tool-$name.log" | tail -1)
      if ((rc == 0)); then say "ok   $tool $name (5 steps): ${errs:-no summary line}"
      else fail "$tool $name exit $rc: ${errs:-$(tail -2 "$work/$tool-$name.log" | tr '\n' ' ')}"; fi
    done
    if [[ -x $build/test_cuda_backend ]]; then
      (cd $build && run_logged "$work/$tool-test_cuda_backend.log" "$(budget 150)" \
        compute-sanitizer --tool $tool --error-exitcode 9 --print-limit 30 ./test_cuda_backend)
      rc=$?
      if ((rc == 0)); then say "ok   $tool test_cuda_backend: $(grep -E 'ERROR SUMMARY' "$work/$tool-test_cuda_backend.log" | tail -1)"
      else fail "$tool test_cuda_backend exit $rc: $(grep -E 'ERROR SUMMARY' "$work/$tool-test_cuda_backend.log" | tail -1)"; fi
    fi
  done
}

stage_bench() {
  ensure_bundle || return
  need_gpu || return
  # BENCH_SECTIONS (bench_fluid --sections) and BENCH_BUDGET_S (seconds, default 540) let one call
  # keep time for a stage after this one (ncu).
  local -a sections=()
  [[ -n "${BENCH_SECTIONS:-}" ]] && sections=(--sections "$BENCH_SECTIONS")
  say "sections: ${BENCH_SECTIONS:-all}; at most $(budget "${BENCH_BUDGET_S:-540}") s"
  BENCH_BACKENDS=cuda BENCH_THREADS=$(nproc) run_logged "$work/bench.log" "$(budget "${BENCH_BUDGET_S:-540}")" \
    bench/run_benchmarks.sh $build --large "${sections[@]}"
  local rc=$? report
  report=$(sed -n 's/^bench: report written to //p' "$work/bench.log" | tail -1)
  [[ -z "$report" ]] && report=$(ls -t bench/results/*.md 2>/dev/null | head -1)
  [[ -n "$report" && -f "$report" ]] && cp "$report" "$work/" && say "report: $report (in the archive)"
  ((rc == 0)) || fail "run_benchmarks exit $rc: $(tail -3 "$work/bench.log" | tr '\n' ' ')"
  [[ -n "$report" && -f "$report" ]] && grep -E '^\| (dam break|SPlisHSPlasH|case)' "$report" | head -20 >>"$summary"
}

stage_ncu() {
  ensure_bundle || return
  need_gpu || return
  need_profilers || return
  # scenes/dam_break.json at r0 = 0.6/82.5 m: 82 x 110 x 110 = 992,200 fluid particles (bench_fluid's
  # "dam break 1000k"), h = 2 r0, dt scaled with r0; no frames.
  local -a scene=(scenes/dam_break.json --set fluid.spacing=0.00727 --set fluid.support_radius=0.01454
    --set solver.dt=0.000545 --set 'output.formats=[]')
  local -a run=("$build/meltwater" run "${scene[@]}" --backend cuda --steps 3 --quiet --out /tmp/meltwater-gpu-ncu)
  $build/meltwater info "${scene[@]}" >"$work/info.txt" 2>&1
  say "scene: $(grep -E '^(particles|memory)' "$work/info.txt" | tr -s ' ' | tr '\n' ';')"
  # Pass 1: every launch's duration (one metric, one replay each).
  # --clock-control none: ncu's default locks the GPU's clocks to base for its replays, and the
  # device tool's METHOD.md asks that the card's clocks be left alone.
  local -a clock=(--clock-control none)
  run_logged "$work/ncu-times.log" "$(budget 240)" ncu "${clock[@]}" --metrics gpu__time_duration.sum \
    --kernel-name-base mangled -f -o "$work/ncu-times" "${run[@]}"
  local rc=$?
  ((rc == 0)) || { fail "ncu pass 1 exit $rc: $(tail -3 "$work/ncu-times.log" | tr '\n' ' ')"; return; }
  ncu -i "$work/ncu-times.ncu-rep" --csv --page raw --print-units base --print-kernel-base mangled \
    >"$work/ncu-times.csv" 2>>"$work/stage.log"
  python3 - "$work/ncu-times.csv" "$work/ncu-top.txt" "$work/ncu-top-names.txt" <<'EOF' || fail "could not read ncu-times.csv"
import csv, subprocess, sys
# ncu's raw page: one row per launch, one column per metric (and a row of units); the details
# page (long form): one row per metric, "Metric Name"/"Metric Unit"/"Metric Value". Either works.
scale = {"ns": 1, "nsecond": 1, "us": 1e3, "usecond": 1e3, "ms": 1e6, "msecond": 1e6, "s": 1e9, "second": 1e9}
lines = [l for l in open(sys.argv[1], errors="replace") if l.startswith('"')]
rows = list(csv.DictReader(lines))
metric = "gpu__time_duration.sum"
launches, raw_unit = {}, "ns"
for r in rows:
    if not (r.get("ID") or "").strip().isdigit():
        raw_unit = (r.get(metric) or raw_unit).strip()  # the raw page's row of units
        continue
    if "Metric Name" in r:
        if r["Metric Name"] != metric:
            continue
        value, unit = r["Metric Value"], (r.get("Metric Unit") or "ns").strip()
    else:
        value, unit = r.get(metric) or "", raw_unit
    try:
        launches[r["ID"]] = (r["Kernel Name"], float(value.replace(",", "")) * scale.get(unit, 1))
    except ValueError:
        pass
total, count = {}, {}
for k, t in launches.values():
    total[k] = total.get(k, 0) + t
    count[k] = count.get(k, 0) + 1
names = sorted(total, key=total.get, reverse=True)
def demangle(ns):
    for tool in ("cu++filt", "c++filt"):
        try:
            res = subprocess.run([tool], input="\n".join(ns), capture_output=True, text=True, check=True)
            return res.stdout.splitlines()
        except Exception:
            pass
    return ns
pretty = demangle(names)
grand = sum(total.values()) or 1
with open(sys.argv[2], "w") as f:
    f.write(f"{len(launches)} launches, {len(names)} kernels, {grand / 1e6:.2f} ms of kernel time (setup + 3 steps)\n")
    f.write("rank | launches | total ms | mean us | share | kernel\n")
    for i, (n, p) in enumerate(zip(names, pretty)):
        f.write(f"{i + 1} | {count[n]} | {total[n] / 1e6:.3f} | {total[n] / count[n] / 1e3:.1f} | "
                f"{100 * total[n] / grand:.1f}% | {p[:300]}\n")
with open(sys.argv[3], "w") as f:
    f.write("\n".join(names[:5]) + "\n")
EOF
  head -12 "$work/ncu-top.txt" | cut -c1-260 >>"$summary"
  # Pass 2: --set basic on each of the five kernels with the most time (the 2nd and 3rd launches).
  local i=0 name
  while read -r name; do
    i=$((i + 1))
    [[ -n "$name" ]] || continue
    if (($(time_left) < 90)); then say "ncu kernel $i and after skipped: $(time_left) s left"; break; fi
    run_logged "$work/ncu-k$i.log" "$(budget 120)" ncu "${clock[@]}" --set basic --kernel-name-base mangled \
      -k "$name" --launch-skip 1 --launch-count 2 -f -o "$work/ncu-k$i" "${run[@]}"
    rc=$?
    if ((rc != 0)); then fail "ncu kernel $i exit $rc"; continue; fi
    ncu -i "$work/ncu-k$i.ncu-rep" --print-kernel-base demangled >"$work/ncu-k$i.txt" 2>&1
    say "-- kernel $i: $(grep -m1 -E '^  [^ ].*\(' "$work/ncu-k$i.txt" | cut -c1-200)"
    grep -E '^ +(Duration|Memory Throughput|DRAM Throughput|Compute \(SM\) Throughput|Registers Per Thread|Block Size|Grid Size|Achieved Occupancy|Theoretical Occupancy) ' \
      "$work/ncu-k$i.txt" | head -9 | tr -s ' ' >>"$summary"
  done <"$work/ncu-top-names.txt"
}

# ---- main ---------------------------------------------------------------------------------------
for s in "$@"; do
  begin_stage "$s"
  if (($(time_left) < 60)); then
    say "skipped: $(time_left) s left before the deadline"
  else
    "stage_$s"
  fi
  end_stage
done
echo "gpu_session: results in $out: $(cd "$out" && ls gpu-*.tar.gz gpu-*.log 2>/dev/null | tr '\n' ' ')"
exit $failed
