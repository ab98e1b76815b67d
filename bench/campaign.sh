#!/usr/bin/env bash
# Whole-command timing of a fault-injection campaign: examples/campaign.yaml, 520 closed-loop
# runs of 10 min at 10 Hz with the fusion pipeline in process, on every core (--jobs = cores), and the
# acceptance check that its outcome matrix has no wrong exclusion.
# Usage: bench/campaign.sh [BUILD_DIR]   (default: build). Prints the load average beside the time.
set -euo pipefail
build="${1:-build}"
tetra="$build/tetra"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
echo "cores: $(nproc); load before: $(cut -d' ' -f1-3 /proc/loadavg)"
start=$(date +%s.%N)
"$tetra" campaign examples/campaign.yaml --out "$out" 2>"$out/progress.log"
end=$(date +%s.%N)
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
runs=$(($(wc -l <"$out/runs.csv") - 1))
echo "runs: $runs in $(echo "$end - $start" | bc) s wall (report and plots included)"
wrong=$(awk -F, 'NR > 1 && $8 == "wrong"' "$out/runs.csv" | wc -l)
echo "wrong exclusions: $wrong"
# The report's sections docs/campaign.md quotes: outcomes, delays, false alarms, pointing.
sed -n '/## Isolation/,/## Wrong/p; /## Detection/,/^CUSUM theory/p; /## False alarms/,/^0 detections\|per hour/p; /## Pointing/,/Recovered/p' \
  "$out/report.md" | grep -v '^!\['
[ "$wrong" -eq 0 ]
