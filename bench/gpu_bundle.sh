#!/usr/bin/env bash
# Runs HERE (the development machine), before a GPU session: builds build-gpu (Release, CUDA for
# sm_90, the CUDA runtime linked statically) and packs what the GPU machine needs into ONE archive,
# gpu-bundle/meltwater-gpu.tar.xz (gpu-bundle/ is git-ignored; name it in the run tool's `carry`).
# The GPU machine has nvcc, CMake and ninja but none of this project's Debian packages (Eigen,
# nanoflann, cxxopts, doctest, nlohmann-json, tinyobjloader, embree3, tbb, openvdb) and cannot download them,
# so nothing is built there: bench/gpu_session.sh unpacks this archive into build-gpu/.
#
# The archive (unpacked into build-gpu/ at the repository root):
#   meltwater, test_*, bench_*   every executable of build-gpu, stripped
#   tests.txt                    the test programs, one a line (each a doctest program, run directly)
#   bundle-lib/                  the non-system shared libraries they need (found with ldd):
#                                embree3, tbb, tinyobjloader, gomp, ...
#   bundle-lib-fallback/         libstdc++ and libgcc_s, used only where the system's are too old
#   bundle-shared/assets/        the meshes of ../shared/assets (the tests and bench_sampling read
#                                MW_SHARED_DIR/assets/meshes; see gpu_session.sh for how it is found)
#   BUNDLE_INFO                  source_dir (baked into the executables), commit, date, glibc needed
#
# Usage: bench/gpu_bundle.sh            (JOBS=N to limit the build's parallelism)
set -euo pipefail
cd "$(dirname "$0")/.."
build="build-gpu"
bundle="gpu-bundle"
archive=$bundle/meltwater-gpu.tar.xz

echo "== configure and build $build (Release, sm_90)"
cmake -S . -B $build -G Ninja -DCMAKE_BUILD_TYPE=Release -DMELTWATER_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 >/dev/null
cmake --build $build -j "${JOBS:-$(nproc)}"

# The source directory CMake baked into the programs (MW_SOURCE_DIR, MW_SHARED_DIR, MW_BINARY).
source_dir=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' $build/CMakeCache.txt)
[[ -n "$source_dir" ]] || { echo "gpu_bundle: no CMAKE_HOME_DIRECTORY in $build/CMakeCache.txt" >&2; exit 1; }

stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bundle-lib" "$stage/bundle-lib-fallback"

echo "== executables"
exes=()
for f in $build/meltwater $build/test_* $build/bench_*; do
  [[ -f "$f" && -x "$f" ]] || continue
  exes+=("$f")
  strip -o "$stage/$(basename "$f")" "$f"
done
[[ ${#exes[@]} -gt 0 && -x "$stage/meltwater" ]] || { echo "gpu_bundle: no executables in $build" >&2; exit 1; }
for f in "${exes[@]}"; do basename "$f"; done | grep '^test_' >"$stage/tests.txt"
echo "${#exes[@]} executables; tests: $(tr '\n' ' ' <"$stage/tests.txt")"

echo "== shared libraries (ldd)"
# System libraries every Linux has (glibc and the loader) stay behind; libstdc++ and libgcc_s go to
# the fallback folder; everything else travels. libcuda is loaded by the static CUDA runtime with
# dlopen (the driver's, on the GPU machine), so ldd does not list it.
declare -A seen=()
while read -r name path; do
  [[ -n "${seen[$name]:-}" ]] && continue
  seen[$name]=1
  case "$name" in
    linux-vdso*|ld-linux*|libc.so*|libm.so*|libpthread.so*|libdl.so*|librt.so*|libresolv.so*|libutil.so*) ;;
    libcuda.so*|libcudart.so*) echo "gpu_bundle: $name is linked dynamically; the bundle expects the static CUDA runtime" >&2; exit 1 ;;
    libstdc++.so*|libgcc_s.so*) cp -L "$path" "$stage/bundle-lib-fallback/$name" ;;
    *) cp -L "$path" "$stage/bundle-lib/$name" && strip --strip-unneeded "$stage/bundle-lib/$name" ;;
  esac
done < <(for f in "${exes[@]}"; do ldd "$f"; done | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}' | sort -u)
missing=$(for f in "${exes[@]}"; do ldd "$f"; done | grep 'not found' | sort -u || true)
[[ -z "$missing" ]] || { echo "gpu_bundle: unresolved libraries here:"$'\n'"$missing" >&2; exit 1; }
ls -1 "$stage/bundle-lib" "$stage/bundle-lib-fallback"

# The newest glibc symbol version any executable or bundled library needs (the GPU machine's
# glibc must be at least that; gpu_session.sh checks it).
glibc_needed=$( { for f in "$stage"/meltwater "$stage"/test_* "$stage"/bench_* "$stage"/bundle-lib/*; do
  objdump -T "$f" 2>/dev/null; done; } | grep -o 'GLIBC_[0-9][0-9.]*' | sed 's/GLIBC_//' | sort -uV | tail -1)

shared_dir="$source_dir/../shared"
if [[ -d "$shared_dir/assets" ]]; then
  mkdir -p "$stage/bundle-shared"
  cp -rL "$shared_dir/assets" "$stage/bundle-shared/"
  echo "== meshes: $(find "$stage/bundle-shared/assets" -type f | wc -l) files from $shared_dir/assets"
else
  echo "== meshes: none ($shared_dir/assets not found); mesh tests will skip there"
fi

{
  echo "source_dir=$source_dir"
  echo "commit=$(git rev-parse HEAD 2>/dev/null || echo unknown)"
  echo "uncommitted_files=$(git status --porcelain 2>/dev/null | grep -v gpu-bundle | wc -l)"
  echo "built=$(date -u +%Y-%m-%dT%H:%M:%SZ) on $(hostname)"
  echo "nvcc=$(nvcc --version 2>/dev/null | sed -n 's/.*release \([0-9.]*\).*/\1/p' || echo unknown)"
  echo "cuda_architectures=$(sed -n 's/^CMAKE_CUDA_ARCHITECTURES:[A-Z]*=//p' $build/CMakeCache.txt)"
  echo "glibc_needed=$glibc_needed"
  echo "glibcxx_here=$(strings "$stage"/bundle-lib-fallback/libstdc++.so* 2>/dev/null | grep -o '^GLIBCXX_[0-9.]*' | sort -uV | tail -1)"
} >"$stage/BUNDLE_INFO"

echo "== archive"
rm -rf "$bundle"
mkdir -p "$bundle"
raw=$(du -sb "$stage" | cut -f1)
tar -C "$stage" -cf - . | xz -9e -T0 >"$archive"
size=$(stat -c %s "$archive")
# What travels with a run: the working tree (tracked and untracked, not ignored) plus the bundle.
tree=$(git ls-files -z --cached --others --exclude-standard | xargs -0 -r stat -c %s 2>/dev/null | awk '{s += $1} END {print s + 0}')
awk -v a="$archive" -v s="$size" -v r="$raw" -v t="$tree" 'BEGIN {
  m = 1048576
  printf "bundle: %s, %.1f MiB (%.1f MiB unpacked); working tree %.1f MiB; together %.1f MiB of the 64 MiB a run carries\n", a, s / m, r / m, t / m, (s + t) / m
}'
if (( size + tree > 56 * 1048576 )); then echo "gpu_bundle: WARNING: close to the 64 MiB limit" >&2; fi

cat <<'EOF'

== GPU session: the run tool calls (timeout_s 600 each, carry ["gpu-bundle"]; every stage unpacks the
   bundle first, so each call also works on a fresh machine). Results come back as
   gpu-STAGE.tar.gz + gpu-STAGE.log. A session has 15 minutes of device time, the machine's start
   included, so the tests and the benchmark go in the first call:
 1. command: bash bench/gpu_session.sh unpack test bench
 2. at once (the machine stays warm 30 s), if the device tool's status shows 6 minutes left:
    command: bash bench/gpu_session.sh sanitize ncu
   Where the tool gives a call less than 600 s (little time left), put GPU_DEADLINE_S=<limit - 60>
   before the command.
EOF
