#!/usr/bin/env bash
# Long logs (docs/formats.md, docs/allan.md): time and peak RSS against the log's length, CSV, HDF5
# (uncompressed, the default) and HDF5 written with `convert --compress` (h5z), for `tetra replay`,
# `tetra allan`, `tetra convert` and reading alone.
#   replay:  orbit logs at 100 Hz, 4 gyros, 1 Hz reference: 30, 120 and 360 min (REPLAY_MINUTES)
#   allan:   static logs at 100 Hz, 4 gyros: 2, 4 and 8 h (ALLAN_HOURS)
#   calibr:  the simulated turntable plan at 100, 1000 and 4000 Hz, 4 gyros (TURNTABLE_HZ), both methods
#            (calibr = sixteen-position, calbatch = batch)
# Each row: command, format, epochs, wall seconds, epochs per second, CPU seconds (user + system, all
# threads), peak RSS [MB]. Wall times depend on the machine's load (printed first and last); CPU seconds
# less so. Reading rows: the best of 3 runs of bench/read_log.
# At the end, the growth table: per command and format, time and peak RSS at the shortest and longest
# log, and the peak RSS's growth per epoch between them (0 B/epoch: memory independent of the length).
# usage: bench/long_logs.sh [BUILD_DIR=build]   (needs tetra, make_allan_log and read_log built; ~1 GB of /tmp)
# BIG=1 adds Allan of 24 h x 1 kHz x 4 gyros from HDF5 (a 3.8 GB HDF5 file, generated on the way).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
T="$build/tetra"
work=$(mktemp -d /tmp/tetra-long-logs-XXXXXX)
trap 'rm -rf "$work"' EXIT
touch "$work/rows.txt" "$work/reads.txt"
REPLAY_MINUTES=${REPLAY_MINUTES:-"30 120 360"}
ALLAN_HOURS=${ALLAN_HOURS:-"2 4 8"}

echo "load: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
printf '%-8s %-5s %10s %8s %12s %8s %10s\n' command fmt epochs wall_s epochs_per_s cpu_s peak_MB
row() {  # NAME FMT EPOCHS -- CMD...
  local name=$1 fmt=$2 epochs=$3
  shift 4
  /usr/bin/time -f "%e %U %S %M" -o "$work/time.txt" "$@" >/dev/null 2>"$work/err.txt" || { cat "$work/err.txt"; exit 1; }
  read -r wall user sys kb <"$work/time.txt"
  awk -v n="$name" -v f="$fmt" -v e="$epochs" -v w="$wall" -v c="$(awk -v u="$user" -v s="$sys" 'BEGIN { print u + s }')" -v k="$kb" \
    'BEGIN { printf "%-8s %-5s %10d %8.2f %12.0f %8.2f %10.1f\n", n, f, e, w, (w > 0 ? e / w : 0), c, k / 1024 }' |
    tee -a "$work/rows.txt"
}
growth_table() {  # from the rows of row(): first and last size of every command and format
  echo
  echo "growth: time and peak RSS against the log's length (first and last size of each command)"
  printf '%-8s %-5s %10s %8s %9s %10s %8s %9s %14s\n' command fmt epochs wall_s peak_MB epochs wall_s peak_MB RSS_B_per_epoch
  awk '{ key = $1 " " $2; if (!(key in first)) { first[key] = $0; order[++n] = key } last[key] = $0 }
    END { for (i = 1; i <= n; ++i) {
      split(first[order[i]], a); split(last[order[i]], b)
      slope = (b[3] > a[3]) ? (b[7] - a[7]) * 1048576 / (b[3] - a[3]) : 0
      printf "%-8s %-5s %10d %8.2f %9.1f %10d %8.2f %9.1f %14.1f\n", a[1], a[2], a[3], a[4], a[7], b[3], b[4], b[7], slope } }' \
    "$work/rows.txt"
}
read_rows() {  # LOG FMT: best of 3 block reads
  local best
  best=$(for _ in 1 2 3; do "$build/bench/read_log" "$1" blocks; done | awk '{ print $6, $3 }' | sort -n | head -1)
  echo "$best" | awk -v f="$2" '{ printf "%-8s %-5s %10d %8.3f %12.0f\n", "read", f, $2, $1, $2 / $1 }'
  local stem
  stem=$(basename "$1")
  echo "${stem%%.*} $2 $best" >>"$work/reads.txt"  # log, format, seconds, epochs
}
read_ratios() {  # HDF5 read against CSV read of the same log
  echo
  echo "read: CSV seconds / HDF5 seconds for the same log (best of 3 each)"
  awk '{ t[$1 " " $2] = $3; if ($2 == "csv") { logs[++n] = $1; epochs[$1] = $4 } }
    END { for (i = 1; i <= n; ++i) { l = logs[i]
      printf "%-10s %10d epochs: CSV %6.3f s, h5 %6.3f s (%5.1fx), h5z %6.3f s (%5.1fx)\n", l, epochs[l],
        t[l " csv"], t[l " h5"], t[l " csv"] / t[l " h5"], t[l " h5z"], t[l " csv"] / t[l " h5z"] } }' \
    "$work/reads.txt"
}
epochs_of() { grep -vc '^#' "$1" | awk '{ print $1 - 1 }'; }

cp bench/seed_as_built.yaml "$work/cal.yaml"  # the seed paper's unit as built

for m in $REPLAY_MINUTES; do
  log="$work/orbit_$m.csv"
  "$T" sim orbit --seed 3 --rate-hz 100 --minutes "$m" --reference-hz 1 -o "$log" >/dev/null 2>&1
  n=$(epochs_of "$log")
  row convert csv2h5 "$n" -- "$T" convert "$log" "$work/orbit_$m.h5"
  row convert csv2h5z "$n" -- "$T" convert --compress "$log" "$work/orbit_$m.h5z.h5"
  read_rows "$log" csv
  read_rows "$work/orbit_$m.h5" h5
  read_rows "$work/orbit_$m.h5z.h5" h5z
  for f in csv h5; do
    # Every replay row starts alike: the previous row's outputs deleted just before (their page-cache
    # pages free for this run's outputs; docs/formats.md, "Replay throughput", on fresh pages).
    rm -f "$work/att.csv" "$work/ev.jsonl"
    row replay "$f" "$n" -- "$T" replay "$work/orbit_$m.$f" --calibration "$work/cal.yaml" \
      --attitude "$work/att.csv" --events "$work/ev.jsonl"
  done
  rm -f "$work/orbit_$m.csv" "$work/orbit_$m.h5" "$work/orbit_$m.h5z.h5"
done

for h in $ALLAN_HOURS; do
  log="$work/static_$h.csv"
  "$build/bench/make_allan_log" "$log" "$h" 100 1 >/dev/null
  n=$(epochs_of "$log")
  "$T" convert "$log" "$work/static_$h.h5"
  "$T" convert --compress "$log" "$work/static_$h.h5z.h5"
  read_rows "$log" csv
  read_rows "$work/static_$h.h5" h5
  read_rows "$work/static_$h.h5z.h5" h5z
  for f in csv h5; do
    row allan "$f" "$n" -- "$T" allan "$work/static_$h.$f" --calibration "$log.cal.yaml" --json "$work/a.json"
  done
  rm -f "$work/static_$h.csv" "$work/static_$h.h5" "$work/static_$h.h5z.h5"
done

# calibrate: the simulated turntable plan at 100, 1000 and 4000 Hz (TURNTABLE_HZ), both methods
for hz in ${TURNTABLE_HZ:-100 1000 4000}; do
  log="$work/turntable_$hz.csv"
  "$T" sim turntable --rate-hz "$hz" -o "$log" >/dev/null 2>&1
  n=$(grep -v '^#' "$log" | tail -n +2 | wc -l)
  row calibr csv "$n" -- "$T" calibrate "$log" -o "$work/cal_out.yaml"
  row calbatch csv "$n" -- "$T" calibrate --method batch "$log" -o "$work/cal_out.yaml"
  rm -f "$log"
done

if [ "${BIG:-0}" = 1 ]; then
  log="$work/static_24h_1k.h5"
  "$build/bench/make_allan_log" "$log" 24 1000 1 >/dev/null
  row allan h5 86400000 -- "$T" allan "$log" --calibration "$log.cal.yaml" --json "$work/a.json"
fi
growth_table
read_ratios
echo "load: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
