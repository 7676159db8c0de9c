#!/usr/bin/env bash
# `make fuzz`: runs each fuzz target of fuzz/ under libFuzzer (with ASan and UBSan) for
# FUZZ_SECONDS (default 300) each, two at a time, starting from the seeds (fuzz/seeds/, scenes/,
# and a checkpoint of a tiny run) and what earlier runs found (build-sanitize/fuzz/<target>/).
# A crash, a hang, an exception other than InputError or a sanitizer report is a finding: its
# input is kept as build-sanitize/fuzz/findings/<target>-..., and the script fails naming it. Once
# fixed, the input goes into fuzz/regressions/<target>/, which every build's ctest replays.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${FUZZ_SECONDS:-300}
targets=(scene_reader obj_reader checkpoint_reader)
./scripts/sanitize_build.sh meltwater "${targets[@]/#/fuzz_}"
build_dir=${SANITIZE_BUILD_DIR:-build-sanitize}
work=$build_dir/fuzz
# A finding is reported once: copy it out (into fuzz/regressions/) before the next run.
rm -rf "$work/findings"
mkdir -p "$work/findings"
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

# The scene reader's dictionary: every key the schema names, quoted as JSON writes it.
"$build_dir/meltwater" schema --json |
  python3 -c 'import json, sys
keys = set()
for row in json.load(sys.stdin):
    for part in row["key"].replace("[]", "").split("."):
        keys.add(part)
for k in sorted(keys):
    print("\"\\\"%s\\\"\"" % k)
for word in ["true", "false", "null", "[", "]", "{", "}", ":", ","]:
    print("\"%s\"" % word)' >"$work/scene_reader.dict"
# A checkpoint with objects of every kind, written by this build.
seed_run=$work/seed_run
rm -rf "$seed_run"
"$build_dir/meltwater" run scenes/floating_boxes.json --set fluid.spacing=0.08 --set fluid.support_radius=0.16 \
  --steps 2 --checkpoint --quiet --out "$seed_run" >/dev/null
mkdir -p "$work/seeds_checkpoint_reader"
cp "$seed_run/checkpoint.mwc" "$work/seeds_checkpoint_reader/floating_boxes.mwc"

seeds_of() {
  case $1 in
    scene_reader) echo fuzz/seeds/scene_reader scenes ;;
    obj_reader) echo fuzz/seeds/obj_reader ;;
    checkpoint_reader) echo fuzz/seeds/checkpoint_reader "$work/seeds_checkpoint_reader" ;;
  esac
}
run_one() {
  local target=$1 corpus=$work/$1/corpus options=()
  mkdir -p "$corpus"
  [[ $target == scene_reader ]] && options+=(-dict="$work/scene_reader.dict")
  [[ $target == checkpoint_reader ]] && options+=(-max_len=200000)
  # shellcheck disable=SC2046
  "$build_dir/fuzz_$target" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=4096 -print_final_stats=1 \
    -artifact_prefix="$work/findings/$target-" "${options[@]}" "$corpus" $(seeds_of "$target") \
    >"$work/$target.log" 2>&1
}
echo "fuzz: ${targets[*]}, ${seconds} s each, two at a time (logs in $work/)"
pids=()
for target in "${targets[@]}"; do
  run_one "$target" & pids+=($!)
  if (( ${#pids[@]} == 2 )); then
    wait "${pids[0]}" || true
    pids=("${pids[@]:1}")
  fi
done
wait || true
failed=0
for target in "${targets[@]}"; do
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$target.log" | tail -1)
  coverage=$(grep -o 'cov: [0-9]*' "$work/$target.log" | tail -1)
  findings=$(ls "$work/findings" 2>/dev/null | grep "^$target-" || true)
  if [[ -n "$findings" ]] || ! grep -q "^Done" "$work/$target.log"; then
    failed=1
    echo "fuzz: $target FAILED after ${runs:-?} inputs: $(grep -m1 -E 'ERROR|runtime error|terminate|Assertion' "$work/$target.log" || echo 'see its log')"
    for f in $findings; do echo "fuzz:   input kept as $work/findings/$f"; done
  else
    echo "fuzz: $target: ${runs:-?} inputs, ${coverage:-cov: ?} edges, no finding"
  fi
done
exit $failed
