#!/usr/bin/env bash
# TDMS memory against the file (docs/formats.md, "TDMS"): a 60 MB file of small integers (7,500,000 rows of
# time_s as int32 and g1..g4 as int8, tests/tdms/make_int8_tdms.py) converted by `tetra convert` to CSV,
# its peak resident memory from /usr/bin/time -v; the table's cells are 7.5e6 x 5 x 8 bytes = 300 MB.
# Usage: bench/tdms_memory.sh [BUILD_DIR]
set -euo pipefail
SRC=$(cd "$(dirname "$0")/.." && pwd)
TETRA=$(realpath "${1:-$SRC/build}")/tetra
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
python3 "$SRC/tests/tdms/make_int8_tdms.py" "$WORK/i8.tdms" 7500000
python3 "$SRC/tests/tdms/make_int8_tdms.py" "$WORK/seg.tdms" 7500000 --segment-rows 1000
for f in i8 seg; do
  /usr/bin/time -v "$TETRA" convert "$WORK/$f.tdms" "$WORK/$f.csv" 2>"$WORK/time.txt"
  rss=$(awk -F': ' '/Maximum resident/ {print $2}' "$WORK/time.txt")
  wall=$(awk -F'): ' '/Elapsed/ {print $2}' "$WORK/time.txt")
  echo "$f.tdms ($(stat -c %s "$WORK/$f.tdms") bytes): peak ${rss} kB, ${wall}"
done
cmp "$WORK/i8.csv" "$WORK/seg.csv" >/dev/null || { sed -n 1,3p "$WORK/i8.csv" "$WORK/seg.csv"; echo differ; exit 1; }
