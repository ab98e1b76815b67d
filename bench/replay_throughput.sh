#!/usr/bin/env bash
# Whole-command replay throughput (docs/formats.md, "Replay throughput"): `tetra replay` of a simulated
# 100 Hz orbit with 4 gyros and a 1 Hz reference (6 h = 2.16 M epochs by default), from CSV and from
# HDF5, outputs included (the attitude CSV is ~270 B per epoch). Best of RUNS runs per format; each row
# prints the wall seconds, epochs per second, CPU seconds (user + system, all threads) and the load
# average beside it (the machine's other work makes wall times longer: compare at the same load).
# Every run writes the same output paths, replacing the previous run's files, as a user re-running a
# replay does; the first run of each format is a warm-up and is not counted. The row "FMT-new" is one
# more run into a new output path after COLD_S seconds idle: on a virtual machine that hands free memory
# back to its host, page-cache pages taken fresh cost several times those the last run just freed
# (766 MB written with dd: ~2 s of system time fresh, ~0.2 s right after deleting a file as large), so a
# first run into a new path can cost more system time than the repeated runs.
# usage: bench/replay_throughput.sh [BUILD_DIR=build]   (MINUTES=360 RUNS=3; ~1.2 GB of /tmp)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
T="$build/tetra"
MINUTES=${MINUTES:-360}
RUNS=${RUNS:-3}
COLD_S=${COLD_S:-20}
work=$(mktemp -d /tmp/tetra-replay-throughput-XXXXXX)
trap 'rm -rf "$work"' EXIT

cp bench/seed_as_built.yaml "$work/cal.yaml"  # the seed paper's unit as built
"$T" sim orbit --seed 3 --rate-hz 100 --minutes "$MINUTES" --reference-hz 1 -o "$work/orbit.csv" >/dev/null 2>&1
"$T" convert "$work/orbit.csv" "$work/orbit.h5" >/dev/null
epochs=$(grep -vc '^#' "$work/orbit.csv" | awk '{ print $1 - 1 }')

load() { cut -d' ' -f1 /proc/loadavg; }
run() {  # FORMAT [OUTPUT_STEM]: one timed replay; prints "wall cpu load"
  local stem=${2:-$work/out}
  /usr/bin/time -f "%e %U %S" -o "$work/time.txt" "$T" replay "$work/orbit.$1" --calibration "$work/cal.yaml" \
    --attitude "$stem.att.csv" --events "$stem.ev.jsonl" >/dev/null 2>"$work/err.txt" || { cat "$work/err.txt"; exit 1; }
  read -r wall user sys <"$work/time.txt"
  echo "$wall $(awk -v u="$user" -v s="$sys" 'BEGIN { print u + s }') $(load)"
}

echo "tetra replay, ${MINUTES}-min orbit at 100 Hz, $epochs epochs, 4 gyros; $(nproc) cores; best of $RUNS"
printf '%-5s %8s %12s %8s %6s   %s\n' fmt wall_s epochs_per_s cpu_s load "all runs (wall_s/cpu_s/load)"
for f in h5 csv; do
  run "$f" >/dev/null  # warm-up: the log in the page cache, the outputs' previous files in place
  runs=$(for _ in $(seq "$RUNS"); do run "$f"; done)
  best=$(echo "$runs" | sort -n | head -1)
  all=$(echo "$runs" | awk '{ printf "%s/%s/%s ", $1, $2, $3 }')
  echo "$best" | awk -v f="$f" -v e="$epochs" -v a="$all" \
    '{ printf "%-5s %8.2f %12.0f %8.2f %6.2f   %s\n", f, $1, ($1 > 0 ? e / $1 : 0), $2, $3, a }'
  sleep "$COLD_S"
  run "$f" "$work/new_$f" | awk -v f="$f-new" -v e="$epochs" \
    '{ printf "%-5s %8.2f %12.0f %8.2f %6.2f\n", f, $1, ($1 > 0 ? e / $1 : 0), $2, $3 }'
  rm -f "$work/new_$f".*
done
