#!/usr/bin/env bash
# Latency of `tetra fusion` on loopback, beside the DDS floor measured by ddsperf in the same run.
#   bench/dds_latency.sh [BUILD_DIR]      (default: build)
# 1. ddsperf ping/pong round trip = two one-way hops, the floor of "write -> service -> read";
# 2. dds_latency against a running `tetra fusion`: last GyroSample write of an epoch -> its Attitude;
# 3. ddsperf again, to bracket the (shared, noisy) machine's load.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
DOMAIN=${TETRA_BENCH_DOMAIN:-201}
RATE=${TETRA_BENCH_RATE:-200}
export CYCLONEDDS_URI="file://$PWD/config/cyclonedds-loopback.xml"
WORK=$(mktemp -d)
FUSION=""
cleanup() { [ -n "$FUSION" ] && kill "$FUSION" 2>/dev/null; wait 2>/dev/null; rm -rf "$WORK"; }
trap cleanup EXIT

floor() {  # MODE: listener (ddsperf's default: handled on the receive thread) or waitset (like tetra)
  ddsperf -i "$DOMAIN" -D 7 pong "$1" >/dev/null 2>&1 &
  local pong=$!
  ddsperf -i "$DOMAIN" -D 6 ping "${RATE}Hz" "$1" 2>&1 | grep -E " 50% " | tail -n 4
  wait "$pong" 2>/dev/null || true
}

echo "== ddsperf ping/pong round trip (two one-way hops), ${RATE} Hz, 12-byte samples, listener"
floor listener
echo "== ddsperf ping/pong round trip, waitset (the wake-up structure of tetra fusion and dds_latency)"
floor waitset
echo "== tetra fusion: last GyroSample write -> Attitude receive, ${RATE} Hz"
"$BUILD/dds_latency" --write-calibration "$WORK/cal.yaml"
printf 'unit: tetra-1\ncalibration: cal.yaml\nsample_rate_hz: %s\n' "$RATE" > "$WORK/fusion.yaml"
"$BUILD/tetra" fusion --config "$WORK/fusion.yaml" --domain "$DOMAIN" --log-level warn > "$WORK/fusion.log" 2>&1 &
FUSION=$!
"$BUILD/dds_latency" --domain "$DOMAIN" --epochs 3000 --rate "$RATE"
kill "$FUSION"; wait "$FUSION" || true; FUSION=""
echo "== ddsperf ping/pong again, listener and waitset"
floor listener
floor waitset
