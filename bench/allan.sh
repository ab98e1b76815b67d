#!/usr/bin/env bash
# Whole-command timing of `tetra allan` on the benchmark log: two hours at 100 Hz x 4 gyros
# (2.88 M samples) in volts, with a calibration — parsing, every tau of the default set (~10 per
# decade, 53 taus from 0.01 s to 3600 s), EDF/chi-squared intervals and the noise fit.
# Targets: < 1 s wall, < 200 MB resident.
#
# usage: bench/allan.sh [BUILD_DIR=build]     (needs make_allan_log and tetra built in BUILD_DIR)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
work=$(mktemp -d /tmp/tetra-allan-bench-XXXXXX)
trap 'rm -rf "$work"' EXIT

log="$work/static_2h.csv"
"$build/bench/make_allan_log" "$log" 2 100 1
echo "log: $(wc -l <"$log") lines, $(du -h "$log" | cut -f1)"
cmd=("$build/tetra" allan "$log" --calibration "$log.cal.yaml" --csv "$work/a.csv" --json "$work/a.json")

echo "--- load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
echo "--- /usr/bin/time -v (one run)"
/usr/bin/time -v "${cmd[@]}" 2>&1 >/dev/null | grep -E "Elapsed|Maximum resident|User time|System time|Percent of CPU"
if command -v hyperfine >/dev/null; then
  echo "--- hyperfine"
  hyperfine --warmup 1 --runs 10 --style basic "${cmd[*]}"
fi
echo "--- with --plot (gnuplot adds its own start-up)"
/usr/bin/time -f "%e s wall, %M KB max resident" "${cmd[@]}" --plot "$work/a.png" >/dev/null
