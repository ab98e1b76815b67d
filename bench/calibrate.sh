#!/usr/bin/env bash
# Whole-command timing of the calibration's performance case: 16 sequences × 10 min at
# 100 Hz (960 000 rows, seed unit, 6 deg/s, 10 revolutions per sequence), CSV reading included.
# Target: under 1 s wall. Usage: bench/calibrate.sh [BUILD_DIR]   (default: build).
# Needs hyperfine; falls back to /usr/bin/time. Prints the machine load: on a shared machine, compare
# user+sys CPU time as well as wall time.
set -euo pipefail
build="${1:-build}"
tetra="$build/tetra"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$tetra" sim turntable --seed 1 --rate-hz 100 --revolutions 10 --out "$out/turntable.csv"
echo "rows: $(grep -v '^#' "$out/turntable.csv" | tail -n +2 | wc -l); size: $(du -h "$out/turntable.csv" | cut -f1)"
echo "load: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
for method in sixteen batch; do
  cmd="$tetra calibrate $out/turntable.csv --method $method -o $out/cal.yaml"
  if command -v hyperfine >/dev/null; then
    hyperfine --warmup 1 --runs 10 --style basic --output=null "$cmd"
  fi
  /usr/bin/time -f "$method: %e s wall, %U s user, %S s sys, %M KB max RSS" $cmd >/dev/null 2>"$out/time.txt" || true
  tail -1 "$out/time.txt"
done
