#!/usr/bin/env bash
# The long sweep of the perturbation families (docs/fdi_validation.md, "Perturbation families"): every family of
# sim/perturbation_families.hpp over RUNS runs each (and each run's unperturbed twin) instead of ctest's
# dozen or so, printing per family: runs, wrong exclusions, exclusions without a fault, LOST, runs whose sigma
# fails the per-run criterion (< 97 % within 3 sigma or a per-axis NEES > 2) where their twin meets it, twins
# failing it, runs honest only from their first flag on, the worst within-3-sigma share and per-axis NEES, the
# mean per-axis NEES, and the delay from the perturbation to its first flag (detection or reference
# rejection), and the runs whose error exceeds the protection level while no alarm stands (>PL) with the
# largest |e|/PL. A run worse than its one twin is judged again over 20 other draws of the simulator's noise
# (tests/fusion/family_campaign.hpp, charged()); those runs are listed with their draws' figures. Exit status
# 1 when a family breaks a promise (the runs are listed).
# RUNS = 300: 2,400 runs (4,800 with the twins); about 3.5 min of CPU.
# Usage: bench/perturbation_sweep.sh [BUILD_DIR] [RUNS] [SEED]   (defaults: build, 300, 1); TETRA_FAMILY_FILTER
#   selects families (a gtest filter, e.g. '*.Reference:*.SecondFault').
# One run listed, its events and figures beside its twin's:
#   TETRA_FAMILY_SHOW=reference:3:197 build/tests/test_perturbation_families --gtest_filter='*ShowOneRun'
# Build: scripts/build.sh --target test_perturbation_families
set -euo pipefail
build="${1:-build}"
runs="${2:-300}"
seed="${3:-1}"
echo "cores: $(nproc); load before: $(cut -d' ' -f1-3 /proc/loadavg)"
start=$(date +%s.%N)
status=0
out=$(mktemp)
trap 'rm -f "$out"' EXIT
TETRA_FAMILY_RUNS="$runs" TETRA_FAMILY_SEED="$seed" "$build/tests/test_perturbation_families" \
  --gtest_filter="${TETRA_FAMILY_FILTER:-PerturbationFamilies.*:-*GeneratorsArePureFunctionsOfSeedAndIndex}" \
  >"$out" 2>&1 || status=$?
grep -m1 '^family ' "$out"
# Each family's line, then its cases' (indented; "(limit)": a case docs/fdi.md states the data cannot cover).
grep -E '^(fault-in-slew|data-path|gap|reference|calibration|calibration-without-noise|second-fault|warm-up|data-sheet|noisy-unit) +[0-9]|^  [a-z].* [0-9]+ +[0-9]+ +[0-9]+ +[0-9]+ ' "$out"
# Runs worse than their one twin, judged over other draws of the noise (charged, or a statistical borderline).
if grep -q '^  over [0-9]* other draws' "$out"; then
  echo "runs worse than their twin, over other draws of the noise:"
  grep -B1 '^  over [0-9]* other draws' "$out" | grep -v '^--$'
fi
if [ "$status" -ne 0 ]; then
  echo "runs that broke a promise:"
  grep -E '^[a-z-]+ #[0-9]+ seed|^  [0-9.]+ % within' "$out" || true
fi
end=$(date +%s.%N)
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "run time: $(echo "$end - $start" | bc) s wall"
exit "$status"
