#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job: `tetra demo` — the simulator, the fusion
# service and the monitor on a private loopback DDS domain, a gyro failure injected mid-run, and a
# summary (docs/dds.md). About 30 s.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
./build/tetra demo
