#!/usr/bin/env bash
# Whole-command timing of the simulator's performance case: a 100-min orbit at 100 Hz,
# 4 gyros, 1 Hz attitude reference — 600 k epochs generated and written to a gyro log.
# Usage: bench/sim_orbit.sh [BUILD_DIR]   (default: build). Needs hyperfine; falls back to /usr/bin/time.
set -euo pipefail
build="${1:-build}"
tetra="$build/tetra"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
cmd="$tetra sim orbit --minutes 100 --rate-hz 100 --reference-hz 1 --seed 1 --out $out/orbit.csv"
if command -v hyperfine >/dev/null; then
  hyperfine --warmup 1 --runs 10 --style basic "$cmd"
  hyperfine --warmup 1 --runs 5 --style basic "$cmd --truth $out/truth.csv"
else
  /usr/bin/time -v $cmd
fi
echo "epochs: $(grep -vc '^#' "$out/orbit.csv") lines incl. header; size: $(du -h "$out/orbit.csv" | cut -f1)"
