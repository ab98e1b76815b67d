#!/usr/bin/env bash
# TDMS read time against the segments (docs/formats.md, "TDMS"): one hour at 100 Hz of 4 gyros and time,
# written by tests/tdms/make_tdms.py as one segment and as a LabVIEW-style stream of 10-row segments,
# each converted by `tetra convert` to /dev/null (read, checked as a gyro log, written as CSV), best of three.
# Usage: bench/tdms_segments.sh [BUILD_DIR]
set -euo pipefail
SRC=$(cd "$(dirname "$0")/.." && pwd)
TETRA=$(realpath "${1:-$SRC/build}")/tetra
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
python3 - "$WORK/hour.csv" <<'PY'
import random, sys
random.seed(1)
with open(sys.argv[1], "w") as f:
    f.write("time_s,g1,g2,g3,g4\n")
    for i in range(360000):
        f.write("%.2f,%.6f,%.6f,%.6f,%.6f\n" % (i / 100, *(random.random() for _ in range(4))))
PY
python3 "$SRC/tests/tdms/make_tdms.py" "$WORK/hour.csv" "$WORK/one.tdms" --one-segment
python3 "$SRC/tests/tdms/make_tdms.py" "$WORK/hour.csv" "$WORK/seg10.tdms" --segment-rows 10
for f in one seg10; do
  best=
  for _ in 1 2 3; do
    start=$(date +%s%N)
    "$TETRA" convert "$WORK/$f.tdms" /dev/null
    ms=$((($(date +%s%N) - start) / 1000000))
    [[ -z $best || $ms -lt $best ]] && best=$ms
  done
  echo "$f.tdms ($(stat -c %s "$WORK/$f.tdms") bytes): ${best} ms"
done
