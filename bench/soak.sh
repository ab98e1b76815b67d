#!/usr/bin/env bash
# Soak: the simulator at RATE Hz into `tetra fusion` for MINUTES in real time, on a private
# loopback domain. Not a ctest test (it runs for an hour); docs/reliability.md has the figures.
#   bench/soak.sh [MINUTES=60] [BUILD_DIR=build] [RATE_HZ=100]
# Measures, and checks:
#   lost epochs      epochs the simulator published − epochs the service accepted       must be 0
#   memory           the service's RSS every 10 s; the growth of its lower envelope < 1 MB per hour
#                    (Cyclone's receive buffer makes RSS a sawtooth: bench/soak_report.py)
#   counters         late, duplicate, out-of-order, gap, unknown gyro, other unit, invalid, absent,
#                    time-rejected epochs, deadlines missed, liveliness lost, sensor restarts  all 0
#   events           a fault-free run: no FDI event at all (a detection would be a false alarm)
#   exit             the service ends on SIGTERM with status 0
# Prints a summary; the raw data (rss.csv, health.jsonl, logs) stays in the work directory it names.
set -euo pipefail
cd "$(dirname "$0")/.."
minutes=${1:-60}
build=${2:-build}
rate=${3:-100}
domain=${TETRA_SOAK_DOMAIN:-203}
tetra="$PWD/$build/tetra"
[ -x "$tetra" ] || { echo "soak: $tetra not built" >&2; exit 1; }
export CYCLONEDDS_URI="file://$PWD/config/cyclonedds-loopback.xml"
work=$(mktemp -d /tmp/tetra-soak.XXXXXX)
fusion_pid=""
sampler_pid=""
monitor_pid=""
cleanup() {
  [ -n "$sampler_pid" ] && kill "$sampler_pid" 2>/dev/null
  [ -n "$monitor_pid" ] && kill "$monitor_pid" 2>/dev/null
  [ -n "$fusion_pid" ] && kill -9 "$fusion_pid" 2>/dev/null
  wait 2>/dev/null || true
}
trap cleanup EXIT

# The simulated unit's own calibration (its as-built truth), so the service is scored on its own merits.
"$tetra" sim turntable --revolutions 0.5 -o "$work/turntable.csv" 2>/dev/null
"$tetra" calibrate "$work/turntable.csv" -o "$work/cal.yaml" >/dev/null 2>&1
printf 'unit: soak-1\ncalibration: cal.yaml\nsample_rate_hz: %s\nspeed: 1\n' "$rate" >"$work/fusion.yaml"

"$tetra" fusion --config "$work/fusion.yaml" --domain "$domain" --log-level warn >"$work/fusion.log" 2>&1 &
fusion_pid=$!
smaps() {  # PID: its mappings with more than 64 kB resident: range, name, kB
  awk '/^[0-9a-f]+-[0-9a-f]+ / {range = $1; name = $6} /^Rss:/ && $2 > 64 {print range, name, $2}' "/proc/$1/smaps"
}
# RSS (total, anonymous, file-backed) and CPU time of the service, and the machine's steal time,
# every 10 s
(
  clk=$(getconf CLK_TCK)
  start=$(date +%s)
  echo "time_s,rss_kB,anon_kB,file_kB,cpu_s,steal_s"
  while kill -0 "$fusion_pid" 2>/dev/null; do
    mem=$(awk '/^VmRSS:/ {r = $2} /^RssAnon:/ {a = $2} /^RssFile:/ {f = $2} END {if (r) print r "," a "," f}' \
      "/proc/$fusion_pid/status" 2>/dev/null || echo "")
    cpu=$(awk -v c="$clk" '{printf "%.2f", ($14 + $15) / c}' "/proc/$fusion_pid/stat" 2>/dev/null || echo "")
    # CPU time the hypervisor took from this machine's CPUs since boot (a VM's stalls show here)
    steal=$(awk -v c="$clk" '/^cpu / {printf "%.2f", $9 / c}' /proc/stat)
    [ -n "$mem" ] && echo "$(($(date +%s) - start)),$mem,$cpu,$steal"
    # Where the memory is, after the warm-up: mappings over 64 kB resident (for the end, see below).
    if [ "$(($(date +%s) - start))" -ge 60 ] && [ ! -e "$work/smaps_60s.txt" ]; then
      smaps "$fusion_pid" >"$work/smaps_60s.txt"
    fi
    sleep 10
  done
) >"$work/rss.csv" &
sampler_pid=$!

# The ground's view during the run, twice a second (the counters as of the simulator's last epoch are
# judged, not those after it stopped, when every gyro is rightly absent).
"$tetra" monitor --jsonl --unit soak-1 --domain "$domain" --period 0.5 >"$work/stream.jsonl" 2>"$work/monitor.err" &
monitor_pid=$!
echo "soak: $minutes min at $rate Hz, domain $domain, work dir $work" >&2
"$tetra" sim orbit --dds --dds-unit soak-1 --domain "$domain" --rate-hz "$rate" --minutes "$minutes" \
  --speed 1 --wait-timeout 30 >"$work/sim.out" 2>"$work/sim.err"
kill "$monitor_pid" 2>/dev/null || true
sleep 2  # the last epoch's latency limit and Health period
"$tetra" monitor --once --jsonl --unit soak-1 --domain "$domain" --timeout 10 >"$work/health.jsonl"
smaps "$fusion_pid" >"$work/smaps_end.txt" 2>/dev/null || true
kill -TERM "$fusion_pid"
fusion_rc=0
wait "$fusion_pid" || fusion_rc=$?
fusion_pid=""
kill "$sampler_pid" 2>/dev/null || true
sampler_pid=""
monitor_pid=""

python3 bench/soak_report.py "$work" "$fusion_rc" "$minutes" "$rate"
