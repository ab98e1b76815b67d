#!/usr/bin/env bash
# `tetra fusion` under valgrind memcheck for a short run (docs/reliability.md).
#   bench/valgrind_fusion.sh [BUILD_DIR=build] [SECONDS=20]
# The simulator publishes SECONDS of an orbit at 100 Hz with a stuck gyro half way (so detection,
# isolation and reconfiguration run too); the service runs under memcheck and is stopped with SIGTERM.
# Pass: no memcheck error and no definitely/indirectly lost block (exit 1 otherwise).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
seconds=${2:-20}
domain=${TETRA_VALGRIND_DOMAIN:-204}
tetra="$PWD/$build/tetra"
export CYCLONEDDS_URI="file://$PWD/config/cyclonedds-loopback.xml"
work=$(mktemp -d /tmp/tetra-valgrind.XXXXXX)
vg_pid=""
cleanup() { [ -n "$vg_pid" ] && kill -9 "$vg_pid" 2>/dev/null; wait 2>/dev/null || true; }
trap cleanup EXIT
"$tetra" sim turntable --revolutions 0.5 -o "$work/turntable.csv" 2>/dev/null
"$tetra" calibrate "$work/turntable.csv" -o "$work/cal.yaml" >/dev/null 2>&1
printf 'unit: vg-1\ncalibration: cal.yaml\nsample_rate_hz: 100\nspeed: 1\nmax_latency_s: 0.2\n' >"$work/fusion.yaml"
valgrind --tool=memcheck --leak-check=full --show-leak-kinds=definite,indirect --errors-for-leak-kinds=definite,indirect \
  --error-exitcode=99 --track-origins=yes --log-file="$work/valgrind.log" \
  "$tetra" fusion --config "$work/fusion.yaml" --domain "$domain" --log-level warn >"$work/fusion.log" 2>&1 &
vg_pid=$!
minutes=$(python3 -c "print($seconds / 60)")
half=$(python3 -c "print($seconds / 2)")
"$tetra" sim orbit --dds --dds-unit vg-1 --domain "$domain" --rate-hz 100 --minutes "$minutes" --speed 1 \
  --fault "gyro=2,kind=stuck,at=$half" --wait-timeout 60 >"$work/sim.out" 2>"$work/sim.err"
"$tetra" monitor --once --jsonl --unit vg-1 --domain "$domain" --timeout 10 >"$work/health.jsonl" || true
kill -TERM "$vg_pid"
rc=0
wait "$vg_pid" || rc=$?
vg_pid=""
grep -E "ERROR SUMMARY|definitely lost|indirectly lost|possibly lost|still reachable|in use at exit" "$work/valgrind.log" | sed 's/^==[0-9]*== /  /'
sed -n 's/^epochs published: /  epochs published: /p' "$work/sim.out"
python3 - "$work/health.jsonl" <<'PY'
import json, sys
for line in open(sys.argv[1]):
    r = json.loads(line)
    if r.get("type") == "health" and "counters" in r:
        print(f"  service: mode {r['mode']}, epochs accepted {r['counters']['epochs_accepted']}, events {r['events_published']}")
PY
if [ "$rc" -ne 0 ]; then
  echo "valgrind_fusion: FAIL (exit status $rc; 99 = memcheck errors); log: $work/valgrind.log" >&2
  exit 1
fi
echo "valgrind_fusion: PASS (log: $work/valgrind.log)"
