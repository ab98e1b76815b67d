#!/bin/sh
# Whole-command timing of `tetra replay` over a 100-min 10 Hz log (60 000 epochs), reading and writing
# included. Usage: bench/replay.sh [BUILD_DIR]   (needs the tetra target built)
set -eu
build=${1:-build}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
# A 100-min orbit with attitude-control motion and its 1 Hz reference, from the simulator.
"$build/tetra" sim orbit --seed 3 --acs-amplitude 0.04 --acs-accel 1e-4 -o "$dir/orbit.csv" >/dev/null 2>&1
cp "$(dirname "$0")/seed_as_built.yaml" "$dir/cal.yaml"  # the seed paper's unit as built
echo "log: $(wc -l < "$dir/orbit.csv") lines, $(du -h "$dir/orbit.csv" | cut -f1)"
cmd="$build/tetra replay $dir/orbit.csv --calibration $dir/cal.yaml --attitude $dir/att.csv --events $dir/ev.jsonl"
if command -v hyperfine >/dev/null 2>&1; then
  hyperfine --warmup 2 --runs 10 "$cmd"
else
  /usr/bin/time -v $cmd 2>&1 | grep -E "Elapsed|Maximum resident"
fi
