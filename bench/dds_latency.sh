#!/usr/bin/env bash
# Latency of `tetra fusion` on loopback, beside the DDS floor measured by ddsperf in the same run.
#   bench/dds_latency.sh [BUILD_DIR]      (default: build)
# 1. ddsperf ping/pong round trip = two one-way hops, the floor of "write -> service -> read";
# 2. dds_latency against a running `tetra fusion`: last GyroSample write of an epoch -> its Attitude,
#    with the service's gyro samples dispatched by a listener (default) and by the waitset, the four
#    samples of an epoch written 100 us apart (asynchronous gyro streams) and back to back;
# 3. ddsperf again, to bracket the (shared, noisy) machine's load.
# 4. each p50 and p99 over the floor's in the same mode, and each maximum.
# FUSION_ARGS: more options for `tetra fusion`, e.g. FUSION_ARGS="--realtime 50" (docs/dds.md, "Real-time
# scheduling"; ddsperf itself keeps the default scheduling). BUSY=1: one busy loop per core but one (on
# every core but the first, at the default scheduling) for the whole run, floors included: the tail with a
# second core busy.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
DOMAIN=${TETRA_BENCH_DOMAIN:-201}
RATE=${TETRA_BENCH_RATE:-200}
read -r -a FUSION_ARGS <<< "${FUSION_ARGS:-}"
export CYCLONEDDS_URI="file://$PWD/config/cyclonedds-loopback.xml"
WORK=$(mktemp -d)
FUSION=""
BUSY_PIDS=()
cleanup() {
  [ -n "$FUSION" ] && kill "$FUSION" 2>/dev/null
  [ ${#BUSY_PIDS[@]} -gt 0 ] && kill "${BUSY_PIDS[@]}" 2>/dev/null
  wait 2>/dev/null
  rm -rf "$WORK"
}
trap cleanup EXIT
if [ "${BUSY:-0}" = 1 ]; then
  for ((cpu = 1; cpu < $(nproc); ++cpu)); do
    taskset -c "$cpu" sh -c 'while :; do :; done' &
    BUSY_PIDS+=($!)
  done
  echo "== BUSY=1: ${#BUSY_PIDS[@]} busy loop(s) on cores 1-$(($(nproc) - 1)) for the whole run"
fi

# floor MODE: ddsperf ping/pong in MODE, listener (ddsperf's default: handled on the receive thread)
# or waitset; prints the median over its one-second reports of p50 and p99, and appends p50 to
# $WORK/floor_MODE.
floor() {
  ddsperf -i "$DOMAIN" -D 7 pong "$1" >/dev/null 2>&1 &
  local pong=$!
  ddsperf -i "$DOMAIN" -D 6 ping "${RATE}Hz" "$1" 2>&1 | grep -E " 50% " | tail -n 4 |
    sed -E 's/.* 50% ([0-9.]+)us .* 99% ([0-9.]+)us .*/\1 \2/' | sort -n |
    awk -v mode="$1" -v out="$WORK/floor_$1" '{p50[NR] = $1; p99[NR] = $2}
      END {m = int((NR + 1) / 2); printf "ddsperf %-8s round trip: p50 %.1f us  p99 %.1f us (median of %d one-second reports)\n", mode, p50[m], p99[m], NR;
           printf "%.1f %.1f\n", p50[m], p99[m] >> out}'
  wait "$pong" 2>/dev/null || true
}

echo "== ddsperf ping/pong round trip (two one-way hops), ${RATE} Hz, 12-byte samples"
floor listener
floor waitset
"$BUILD/dds_latency" --write-calibration "$WORK/cal.yaml"
# run DISPATCH RECEIVE SPACING_US: a service with `gyro_dispatch: DISPATCH`, this program receiving
# its Attitude the RECEIVE way, the four samples of an epoch SPACING_US apart (0: one burst).
run() {
  printf 'unit: tetra-1\ncalibration: cal.yaml\nsample_rate_hz: %s\ngyro_dispatch: %s\n' "$RATE" "$1" \
    > "$WORK/fusion.yaml"
  "$BUILD/tetra" fusion --config "$WORK/fusion.yaml" --domain "$DOMAIN" --log-level warn "${FUSION_ARGS[@]}" \
    > "$WORK/fusion.log" 2>&1 &
  FUSION=$!
  echo "-- service gyro_dispatch $1 ${FUSION_ARGS[*]}, Attitude received by a $2, samples ${3} us apart"
  "$BUILD/dds_latency" --domain "$DOMAIN" --epochs 3000 --rate "$RATE" --receive "$2" --gyro-spacing-us "$3" |
    tee -a "$WORK/tetra_$2"
  kill "$FUSION"; wait "$FUSION" || true; FUSION=""
  grep -- "--realtime" "$WORK/fusion.log" || true  # what --realtime could not apply
}
echo "== tetra fusion: last GyroSample write -> Attitude receive, ${RATE} Hz"
echo "   (compare listener with ddsperf's listener mode, waitset with its waitset mode)"
run listener listener 100   # four asynchronous gyro streams
run listener listener 0     # one writer, four samples back to back
run waitset waitset 100
run waitset waitset 0
echo "== ddsperf ping/pong again"
floor listener
floor waitset
echo "== p50 and p99 / DDS floor (the floor: mean of the two ddsperf runs in the same mode), and the max"
for mode in listener waitset; do
  read -r f50 f99 < <(awk '{a += $1; b += $2} END {printf "%.1f %.1f\n", a / NR, b / NR}' "$WORK/floor_$mode")
  sed -E 's/.* p50 ([0-9.]+) us .* p99 ([0-9.]+) us +max ([0-9.]+) us.*/\1 \2 \3/' "$WORK/tetra_$mode" |
    while read -r p50 p99 max; do
      awk -v m="$mode" -v a="$p50" -v b="$p99" -v x="$max" -v f="$f50" -v g="$f99" 'BEGIN {
        printf "%-8s p50 %6.1f us / floor %6.1f us = %.2f   p99 %7.1f us / floor %6.1f us = %.2f   max %8.1f us\n",
               m, a, f, a / f, b, g, b / g, x}'
    done
done
