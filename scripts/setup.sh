#!/usr/bin/env bash
# Idempotent set-up: installs only the Debian packages that are missing, then configures CMake in
# Release in build/. Safe to run any number of times; `make demo|test|bench` run it first.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(cmake g++ make ninja-build libeigen3-dev libnanoflann-dev libcxxopts-dev doctest-dev
          nlohmann-json3-dev libtinyobjloader-dev libembree-dev libtbb-dev python3-meshio)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "setup: missing Debian packages: ${missing[*]}" >&2
    echo "setup: run as root, or: sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

build_dir=${BUILD_DIR:-build}
cuda=${MELTWATER_CUDA:-AUTO}
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
# Configure when there is no build yet, or when an existing one is not Release (a Debug build
# left in the folder would make every figure the demo and the benchmarks print meaningless).
build_type=$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$build_dir/CMakeCache.txt" 2>/dev/null || true)
if [[ ! -f "$build_dir/CMakeCache.txt" || "$build_type" != "Release" ]]; then
  [[ -f "$build_dir/CMakeCache.txt" ]] && echo "setup: $build_dir was configured as '${build_type:-none}'; reconfiguring as Release"
  cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DMELTWATER_CUDA="$cuda" \
        ${CMAKE_CUDA_ARCHITECTURES:+-DCMAKE_CUDA_ARCHITECTURES="$CMAKE_CUDA_ARCHITECTURES"} >/dev/null
  echo "setup: configured $build_dir (Release, CUDA $cuda)"
fi
