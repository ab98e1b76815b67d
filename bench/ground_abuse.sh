#!/usr/bin/env bash
# The ground station under abuse (docs/ground.md, figures): 1,000 event streams held (never read),
# 100 slow clients (a byte a second), 10 units at 100 Hz streaming (bench/ground_load_publisher),
# 1,000 API requests spread over 60 s, then 50 commands to a tetra fusion; prints the API's latency
# (p50, p95, p99), the commands' round trips and the ground's resident memory.
#   bench/ground_abuse.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
cmake --build "$build" --target tetra ground_load_publisher >/dev/null
exec python3 tests/ground/abuse_test.py --tetra "$build/tetra" --source . --publisher "$build/ground_load_publisher" \
  --requests 1000 --spread 60 --commands 50
