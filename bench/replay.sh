#!/bin/sh
# Whole-command timing of `tetra replay` over a 100-min 10 Hz log (60 000 epochs), reading and writing
# included. Usage: bench/replay.sh [BUILD_DIR]   (needs the tetra target built)
set -eu
build=${1:-build}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
# A 100-min orbit with attitude-control motion and its 1 Hz reference, from the simulator.
"$build/tetra" sim orbit --seed 3 --acs-amplitude 0.04 --acs-accel 1e-4 -o "$dir/orbit.csv" >/dev/null 2>&1
cat > "$dir/cal.yaml" <<'YAML'
unit: seed-as-built
method: seed-tables-4-5
gyros:
  - {id: 1, scale_factor_V_per_dps: 0.0730, bias_V: 0.0002, axis: [0.55526, -0.00146, 0.83167], noise: {arw_dps_rtHz: 3.0e-5}}
  - {id: 2, scale_factor_V_per_dps: 0.0785, bias_V: 0.0004, axis: [0.42638, 0.78516, -0.44914], noise: {arw_dps_rtHz: 3.0e-5}}
  - {id: 3, scale_factor_V_per_dps: 0.0880, bias_V: 0.0002, axis: [0.51389, -0.74179, -0.43088], noise: {arw_dps_rtHz: 3.0e-5}}
  - {id: 4, scale_factor_V_per_dps: 0.0775, bias_V: -0.0003, axis: [0.99999, -0.00094, 0.00065], noise: {arw_dps_rtHz: 3.0e-5}}
YAML
echo "log: $(wc -l < "$dir/orbit.csv") lines, $(du -h "$dir/orbit.csv" | cut -f1)"
cmd="$build/tetra replay $dir/orbit.csv --calibration $dir/cal.yaml --attitude $dir/att.csv --events $dir/ev.jsonl"
if command -v hyperfine >/dev/null 2>&1; then
  hyperfine --warmup 2 --runs 10 "$cmd"
else
  /usr/bin/time -v $cmd 2>&1 | grep -E "Elapsed|Maximum resident"
fi
