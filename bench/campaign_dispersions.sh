#!/usr/bin/env bash
# Which dispersion moves the outcome: the scenario of examples/campaign_dispersed.yaml with one
# parameter dispersed at a time (docs/campaign.md, "Measured"). Per parameter, the outcomes of 10 runs of
# 10 min with a stuck gyro 1 at 100 s, and the false alarms in 10 fault-free runs and 10 with the fault
# only at 590 s (3.3 h of flight before any onset).
# The bias line uses a 1e-6 V 1-sigma (five times the example unit's) to show the pipeline's sensitivity.
# Usage: bench/campaign_dispersions.sh [BUILD_DIR]   (default: build)
set -euo pipefail
build="${1:-build}"
tetra="$(realpath "$build/tetra")"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
scenario="$(realpath examples/sim/closed_loop_calibrated.yaml)"
echo "cores: $(nproc); load before: $(cut -d' ' -f1-3 /proc/loadavg)"
while IFS= read -r law; do
  name="${law%%:*}"
  for onset in 100 590; do
    spec="$out/$name-$onset.yaml"
    printf 'scenarios: [%s]\nduration_s: 600\nkinds: [stuck]\ngyros: [1]\nonsets_s: [%s]\n' "$scenario" "$onset" >"$spec"
    printf 'seeds: {first: 1, count: 10}\nfault_free: %s\n' "$([ $onset = 590 ] && echo true || echo false)" >>"$spec"
    [ "$name" = none ] || printf 'dispersions:\n  seed: 1\n  %s\n' "$law" >>"$spec"
    "$tetra" campaign "$spec" --out "$out/$name-$onset" --jobs "$(nproc)" --no-report 2>/dev/null
  done
  outcomes=$(awk -F, 'NR > 1 { n[$8]++ } END { for (o in n) printf " %s %d", o, n[o] }' "$out/$name-100/runs.csv")
  alarms=$(awk -F, 'NR > 1 { fa += $13; h += $14 / 3600 } END { printf "%d false alarms in %.1f h", fa, h }' \
    "$out/$name-590/runs.csv")
  printf '%-30s stuck:%s; %s\n' "$name" "$outcomes" "$alarms"
done <<'LAWS'
none: nominal
unit.scale_factor_ppm: calibration
unit.bias_V: {normal: [0, 1.0e-6]}
unit.axis: calibration
unit.arw_factor: {truncated_normal: [1.0, 0.1, 0.7, 1.5]}
unit.bias_instability_factor: {uniform: [0.5, 2.0]}
spacecraft.inertia_percent: {truncated_normal: [0, 3, -10, 10]}
spacecraft.inertia_axes_deg: {normal: [0, 1]}
disturbance.constant_Nm: {normal: [0, 1.0e-6]}
reference.noise_arcsec: {uniform: [3, 10]}
reference.latency_s: {uniform: [0, 0.2]}
LAWS
