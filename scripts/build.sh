#!/usr/bin/env bash
# Configures and builds tetra in ./build (Release). Extra arguments go to cmake --build.
# TETRA_BUILD_TESTS=OFF configures without the tests and benchmarks (and their packages); default ON.
# ccache is used when installed (rebuilds of unchanged sources are then near free).
set -euo pipefail
cd "$(dirname "$0")/.."
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
# Ninja when installed (setup.sh installs it): it compiles a library's sources while the libraries it links
# are still being built, where make waits for each of them, so both cores stay busy to the end of a first
# build. A build folder configured before keeps its generator.
generator=()
if [ ! -f build/CMakeCache.txt ] && command -v ninja >/dev/null; then
  generator=(-G Ninja)
fi
tests=${TETRA_BUILD_TESTS:-ON}
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DTETRA_BUILD_TESTS="$tests" \
  -DTETRA_BUILD_BENCH="$tests" "${launcher[@]}" >/dev/null
cmake --build build -j "$(nproc)" "$@"
