#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job: calibrates the example
# turntable data and prints the result.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
./build/tetra calibrate examples/turntable.csv -o build/calibration.yaml --compare examples/factory.yaml
