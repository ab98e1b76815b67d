#!/usr/bin/env bash
# The long sweep of the one-fault, sigma-after-isolation and data-path campaigns (docs/fdi_validation.md, "One
# fault, one exclusion", "Bias states repaired at isolation", "Data path"): the ctest cases of
# tests/fusion/test_isolation_adversarial.cpp run over SEEDS seeds each instead of ctest's one or two.
# SEEDS = 5: 1,800 one-fault runs, 1,350 sigma runs, 240 data-path runs (3,390 in all; about 35 s wall at
# load 15 on 2 cores).
# Usage: bench/one_fault_sweep.sh [BUILD_DIR] [SEEDS]   (defaults: build, 5)
# Build: scripts/build.sh --target test_isolation_adversarial
set -euo pipefail
build="${1:-build}"
seeds="${2:-5}"
echo "cores: $(nproc); load before: $(cut -d' ' -f1-3 /proc/loadavg)"
start=$(date +%s.%N)
status=0
TETRA_ONE_FAULT_SEEDS="$seeds" "$build/tests/test_isolation_adversarial" \
  --gtest_filter='*OneFaultNeverCostsASecondGyro:*SigmaHonestAfterAReconfiguration*:*DataPathFaultsAreNotGyroFaults' ||
  status=$?
end=$(date +%s.%N)
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "run time: $(echo "$end - $start" | bc) s wall"
exit "$status"
