#!/usr/bin/env bash
# Configures and builds tetra in ./build (Release). Extra arguments go to cmake --build.
# ccache is used when installed (rebuilds of unchanged sources are then near free).
set -euo pipefail
cd "$(dirname "$0")/.."
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
cmake --build build -j "$(nproc)" "$@"
