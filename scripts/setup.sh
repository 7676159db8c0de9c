#!/usr/bin/env bash
# Idempotent set-up: installs only the Debian packages that are missing, then configures CMake in
# Release in build/. Safe to run any number of times; `make demo|test|bench` run it first.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(cmake g++ make ninja-build libeigen3-dev libnanoflann-dev libcxxopts-dev doctest-dev
          nlohmann-json3-dev libtinyobjloader-dev libembree-dev libtbb-dev python3-meshio
          libopenvdb-dev libboost-dev libboost-iostreams-dev strace pkg-config libstb-dev
          pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib python3-openvdb)
# libboost-dev, libboost-iostreams-dev: OpenVDB's headers include Boost's and its CMake find module
# asks for Boost.Iostreams, neither of which Debian 12's libopenvdb-dev pulls in. strace: a test
# watches the program flush its outputs to disk. libstb-dev: PNG writing and the pictures' font.
# pybind11-dev, python3-*: the Python module and its tests; python3-openvdb reads .vdb frames back.
./scripts/install_packages.sh "${packages[@]}"
[[ "${1:-}" == "--packages-only" ]] && exit 0

build_dir=${BUILD_DIR:-build}
cuda=${MELTWATER_CUDA:-AUTO}
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
# Configure when there is no build yet, or when an existing one is not Release (a Debug build
# left in the folder would make every figure the demo and the benchmarks print meaningless).
# Also when MELTWATER_CUDA or CMAKE_CUDA_ARCHITECTURES is given and differs from what the
# existing build was configured with, so that the variables are never silently ignored.
cached() { sed -n "s/^$1:[A-Z]*=//p" "$build_dir/CMakeCache.txt" 2>/dev/null || true; }
build_type=$(cached CMAKE_BUILD_TYPE)
reason=""
if [[ -f "$build_dir/CMakeCache.txt" ]]; then
  [[ "$build_type" != "Release" ]] && reason="it was configured as '${build_type:-none}'"
  [[ -n "${MELTWATER_CUDA:-}" && "$MELTWATER_CUDA" != "$(cached MELTWATER_CUDA)" ]] &&
    reason="MELTWATER_CUDA=$MELTWATER_CUDA differs from its '$(cached MELTWATER_CUDA)'"
  [[ -n "${CMAKE_CUDA_ARCHITECTURES:-}" && "$CMAKE_CUDA_ARCHITECTURES" != "$(cached CMAKE_CUDA_ARCHITECTURES)" ]] &&
    reason="CMAKE_CUDA_ARCHITECTURES=$CMAKE_CUDA_ARCHITECTURES differs from its '$(cached CMAKE_CUDA_ARCHITECTURES)'"
fi
if [[ ! -f "$build_dir/CMakeCache.txt" || -n "$reason" ]]; then
  [[ -n "$reason" ]] && echo "setup: reconfiguring $build_dir: $reason"
  # A reconfigured build keeps its CUDA choice unless MELTWATER_CUDA is given.
  cuda_option=(-DMELTWATER_CUDA="$cuda")
  [[ -f "$build_dir/CMakeCache.txt" && -z "${MELTWATER_CUDA:-}" ]] && cuda_option=() && cuda=$(cached MELTWATER_CUDA)
  cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "${cuda_option[@]}" \
        ${CMAKE_CUDA_ARCHITECTURES:+-DCMAKE_CUDA_ARCHITECTURES="$CMAKE_CUDA_ARCHITECTURES"} >/dev/null
  echo "setup: configured $build_dir (Release, CUDA $cuda)"
fi
