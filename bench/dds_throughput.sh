#!/usr/bin/env bash
# Sustained load of `tetra fusion` on loopback (whole-command measurement).
#   bench/dds_throughput.sh [BUILD_DIR] [SECONDS]     (defaults: build, 60)
# 1. 2 kHz epochs (8 k samples/s) in real time for SECONDS: epochs published by the simulator vs
#    epochs the service accepted and attitudes the simulator got back (zero lost is the goal);
# 2. 100 Hz for SECONDS: the service's CPU share of one core and its peak resident memory (/proc).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
SECONDS_RUN=${2:-60}
DOMAIN=${TETRA_BENCH_DOMAIN:-202}
export CYCLONEDDS_URI="file://$PWD/config/cyclonedds-loopback.xml"
WORK=$(mktemp -d)
FUSION=""
cleanup() { [ -n "$FUSION" ] && kill "$FUSION" 2>/dev/null; wait 2>/dev/null; [ -n "${TETRA_BENCH_KEEP:-}" ] && cp -r "$WORK" "$TETRA_BENCH_KEEP"; rm -rf "$WORK"; }
trap cleanup EXIT
MINUTES=$(python3 -c "print($SECONDS_RUN/60)")
"$BUILD/dds_latency" --write-calibration "$WORK/cal.yaml"   # the simulator's unit (seed as built)
sed -i 's/^unit: .*/unit: tetra-1/' "$WORK/cal.yaml"
# The simulated body sits still in the lab: the service removes the Earth rate of the simulator's
# latitude (ground-test mode) and starts from the true initial attitude, so the simulator's score
# is the fusion's error (without it the Earth rate alone, 15 deg/h, reads as 0.25 deg after 60 s).
"$BUILD/tetra" sim static --minutes 0.01 -o "$WORK/q0.csv" --truth "$WORK/truth.csv"
LATITUDE=$(sed -n 's/^# latitude_deg=//p' "$WORK/q0.csv")
Q0=$(grep -v '^#' "$WORK/truth.csv" | awk -F, 'NR == 2 {printf "[%s, %s, %s, %s]", $2, $3, $4, $5}')

run() {  # RATE_HZ: service + simulator for SECONDS_RUN, then the service's counters
  local rate=$1
  printf 'unit: tetra-1\ncalibration: cal.yaml\nsample_rate_hz: %s\nmax_latency_s: 0.01\npipeline:\n  initial_q_wxyz: %s\n  latitude_deg: %s\n' \
    "$rate" "$Q0" "$LATITUDE" > "$WORK/fusion.yaml"
  "$BUILD/tetra" fusion --config "$WORK/fusion.yaml" --domain "$DOMAIN" --log-level warn > "$WORK/fusion.log" 2>&1 &
  FUSION=$!
  local started=$(date +%s.%N)
  "$BUILD/tetra" sim static --dds --dds-unit tetra-1 --domain "$DOMAIN" --rate-hz "$rate" --minutes "$MINUTES" \
    --speed 1 2> "$WORK/sim.err" | sed "s/^/  sim: /" || { cat "$WORK/sim.err" "$WORK/fusion.log" "$WORK/fusion.time"; exit 1; }
  "$BUILD/tetra" monitor --once --jsonl --unit tetra-1 --domain "$DOMAIN" > "$WORK/health.jsonl"
  python3 - "$WORK/health.jsonl" <<'PY'
import json, sys
for line in open(sys.argv[1]):
    h = json.loads(line)
    if h.get("type") != "health":
        continue
    c = h["counters"]
    print("  service: epochs accepted %d (rejected %d), samples accepted %d, absent %d, late %d, duplicate %d, "
          "out of order %d, gap %d, deadlines missed %d" % (c["epochs_accepted"], c["epochs_rejected_time"], c["samples_accepted"],
          c["samples_absent"], c["samples_late"], c["samples_duplicate"], c["samples_out_of_order"],
          c["samples_gap"], c["deadlines_missed"]))
PY
  # CPU time and peak resident memory of the service over its whole life so far (/proc).
  python3 - "$FUSION" "$started" <<'PY'
import os, sys, time
pid, started = sys.argv[1], float(sys.argv[2])
fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
ticks = os.sysconf("SC_CLK_TCK")
cpu_s = (int(fields[11]) + int(fields[12])) / ticks
elapsed = time.time() - started
hwm = [l for l in open(f"/proc/{pid}/status") if l.startswith("VmHWM")][0].split()[1]
print("  service: CPU %.2f s over %.1f s = %.1f %% of one core; peak RSS %.1f MB" %
      (cpu_s, elapsed, 100 * cpu_s / elapsed, int(hwm) / 1024))
PY
  kill -TERM "$FUSION"; wait "$FUSION" || true; FUSION=""
}

echo "== 2 kHz epochs (8 k samples/s), ${SECONDS_RUN} s real time"
run 2000
echo "== 100 Hz, ${SECONDS_RUN} s real time"
run 100
