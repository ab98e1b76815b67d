#!/usr/bin/env bash
# Installs what is missing, builds the program, and runs the main job: `tetra demo` — the simulator,
# the fusion service and the monitor on a private loopback DDS domain, a gyro failure injected mid-run,
# and a summary (docs/dds.md). About 30 s once built. Only the `tetra` program is built, configured
# without the tests and benchmarks (scripts/test.sh builds those).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
TETRA_BUILD_TESTS=OFF bash scripts/build.sh --target tetra
./build/tetra demo
