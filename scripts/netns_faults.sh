#!/usr/bin/env bash
# Multi-host faults (issue 7.5): simulator, fusion service and monitor each in its own network
# namespace, joined by veth links to a bridge in a fourth namespace; Cyclone DDS configured for those
# addresses (unicast discovery, no multicast). Faults injected by taking a link down on the bridge side:
#   1. sensor link cut    -> the service sees its gyros absent -> LOST; restored -> NOMINAL again
#   2. monitor link cut   -> a fault happens meanwhile; on reconnect the monitor receives the event
#                            (FdiEvent and Health are transient-local, reliable)
#   3. service kill -9 and restart -> the monitor sees the new service publish (fresh counters)
#   netns_faults.sh TETRA_BINARY [WORK_DIR]
# Needs root (ip netns). Exit 0 pass, 1 fail, 77 skipped (not root). The namespaces are always torn
# down (trap on EXIT), also when a check fails or the script is interrupted.
set -euo pipefail
tetra=${1:?usage: netns_faults.sh TETRA_BINARY [WORK_DIR]}
tetra=$(cd "$(dirname "$tetra")" && pwd)/$(basename "$tetra")
work=${2:-$(mktemp -d /tmp/tetra-netns.XXXXXX)}
mkdir -p "$work"

if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: netns_faults needs root (ip netns add); run it as root: sudo $0 $tetra"
  exit 77
fi
command -v ip >/dev/null || { echo "netns_faults: iproute2 'ip' not found" >&2; exit 1; }

tag=t$$                      # namespace and link names unique to this run
ns_hub=${tag}hub ns_sim=${tag}sim ns_fus=${tag}fus ns_mon=${tag}mon
pids=()
cleanup() {
  local rc=$?
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  for ns in "$ns_sim" "$ns_fus" "$ns_mon" "$ns_hub"; do ip netns del "$ns" 2>/dev/null || true; done
  if [ "$rc" -ne 0 ]; then echo "netns_faults: FAILED (logs kept in $work)" >&2; fi
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

log() { printf '[%6.1f s] %s\n' "$(echo "$(date +%s.%N) - $t0" | bc)" "$*"; }
fail() { echo "netns_faults: FAIL: $*" >&2; exit 1; }
t0=$(date +%s.%N)

# --- network: hub bridge + one veth pair per host -----------------------------------------------
ip netns add "$ns_hub"
ip -n "$ns_hub" link add br0 type bridge
ip -n "$ns_hub" link set br0 up
ip -n "$ns_hub" link set lo up
declare -A addr=([sim]=10.77.0.1 [fus]=10.77.0.2 [mon]=10.77.0.3)
for host in sim fus mon; do
  ns=${tag}${host}
  ip netns add "$ns"
  ip link add "${tag}${host}h" netns "$ns_hub" type veth peer name eth0 netns "$ns"
  ip -n "$ns_hub" link set "${tag}${host}h" master br0 up
  ip -n "$ns" link set lo up
  ip -n "$ns" addr add "${addr[$host]}/24" dev eth0
  ip -n "$ns" link set eth0 up
  cat >"$work/cyclone-$host.xml" <<XML
<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any">
  <General><Interfaces><NetworkInterface name="eth0"/></Interfaces><AllowMulticast>false</AllowMulticast></General>
  <Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>30</MaxAutoParticipantIndex>
    <Peers><Peer Address="${addr[sim]}"/><Peer Address="${addr[fus]}"/><Peer Address="${addr[mon]}"/></Peers>
  </Discovery>
</Domain></CycloneDDS>
XML
done
ip netns exec "$ns_sim" ping -c1 -W2 "${addr[fus]}" >/dev/null || fail "no IP connectivity sim -> fusion"
ip netns exec "$ns_mon" ping -c1 -W2 "${addr[fus]}" >/dev/null || fail "no IP connectivity monitor -> fusion"
log "namespaces $ns_sim $ns_fus $ns_mon over bridge in $ns_hub"
link() { ip -n "$ns_hub" link set "${tag}$1h" "$2"; log "link $1 $2"; }
in_ns() {  # host, command...
  local host=$1
  shift
  ip netns exec "${tag}${host}" env CYCLONEDDS_URI="file://$work/cyclone-$host.xml" "$@"
}

# --- the unit: a calibration from a simulated turntable run, the service's configuration ----------
"$tetra" sim turntable --revolutions 0.25 -o "$work/turntable.csv" 2>/dev/null
"$tetra" calibrate "$work/turntable.csv" -o "$work/cal.yaml" >/dev/null 2>&1 || fail "calibrate"
rate=50
cat >"$work/fusion.yaml" <<YAML
unit: netns-1
calibration: cal.yaml
sample_rate_hz: $rate
speed: 1
health_period_s: 0.2
YAML
domain=9

start_fusion() {
  in_ns fus "$tetra" fusion --config "$work/fusion.yaml" --domain $domain >>"$work/fusion.log" 2>&1 &
  fusion_pid=$!
  pids+=("$fusion_pid")
}
start_fusion
in_ns mon "$tetra" monitor --unit netns-1 --jsonl --period 0.2 --domain $domain >"$work/monitor.jsonl" 2>"$work/monitor.log" &
pids+=($!)
# Timeline in simulated (= wall, speed 1) seconds after the simulator starts:
#   8-13 sensor link down | 18-26 monitor link down, gyro 2 stuck from 20 | 30 service killed, 32 restarted
in_ns sim "$tetra" sim orbit --dds --dds-unit netns-1 --domain $domain --rate-hz $rate --minutes 0.7 \
  --reference-hz 0 --fault gyro=2,kind=stuck,at=20 --wait-timeout 30 >"$work/sim.log" 2>&1 &
sim_pid=$!
pids+=("$sim_pid")

# Wait until the service publishes attitude for the simulator's epochs (NOMINAL on the monitor).
wait_for() {  # seconds, grep pattern on monitor.jsonl, what
  local deadline=$(($(date +%s) + $1))
  until grep -q -- "$2" "$work/monitor.jsonl" 2>/dev/null; do
    [ "$(date +%s)" -lt "$deadline" ] || fail "timeout waiting for $3"
    sleep 0.2
  done
}
wait_for 30 '"mode": "NOMINAL"' "the service to run NOMINAL"
ts=$(date +%s.%N)
at() { sleep "$(echo "$ts + $1 - $(date +%s.%N)" | bc | sed 's/^-.*/0/')"; }
log "service NOMINAL; fault schedule starts"

at 8
lines_before_cut=$(wc -l <"$work/monitor.jsonl")
link sim down
at 13
link sim up
at 16
sed -n "$((lines_before_cut + 1)),\$p" "$work/monitor.jsonl" >"$work/after_sensor_cut.jsonl"
grep -q '"mode": "LOST"' "$work/after_sensor_cut.jsonl" || fail "sensor link cut: the monitor never saw LOST"
log "check: sensor link cut -> LOST seen"

at 18
link mon down
lines_mon_cut=$(wc -l <"$work/monitor.jsonl")
at 26
link mon up
at 29
sed -n "$((lines_mon_cut + 1)),\$p" "$work/monitor.jsonl" >"$work/after_monitor_cut.jsonl"
grep -q '"event": "isolated"' "$work/after_monitor_cut.jsonl" ||
  fail "monitor link cut: the isolation of gyro 2 (stuck at 20 s) did not reach the monitor after reconnect"
log "check: monitor reconnect -> event history caught up"

at 30
kill -9 "$fusion_pid"
log "service killed (SIGKILL)"
at 32
lines_restart=$(wc -l <"$work/monitor.jsonl")
start_fusion
log "service restarted"
at 38
kill -9 "$fusion_pid" 2>/dev/null || true
wait "$sim_pid" 2>/dev/null || true
sed -n "$((lines_restart + 1)),\$p" "$work/monitor.jsonl" >"$work/after_restart.jsonl"
# A new service starts its counters at zero: its first Health shows fewer accepted epochs than the
# last Health of the old one.
python3 - "$work/monitor.jsonl" "$lines_restart" <<'PY' || fail "service restart: the monitor did not see the new service"
import json, sys
path, cut = sys.argv[1], int(sys.argv[2])
rows = [json.loads(l) for l in open(path) if l.strip()]
health = [(i, r) for i, r in enumerate(rows) if r.get("type") == "health" and "counters" in r]
before = [r["counters"]["epochs_accepted"] for i, r in health if i < cut]
after = [r["counters"]["epochs_accepted"] for i, r in health if i >= cut]
if not before or not after: sys.exit("no health before or after the restart")
drop = [a for a in after if a < before[-1]]
if not drop: sys.exit("no health with fresh counters after the restart")
grow = [a for a in after if a > min(drop)]
if not grow: sys.exit("the new service's counters never grew")
print(f"old service last epochs_accepted={before[-1]}, new service first={min(drop)}, then {max(after)}")
PY
log "check: service restart -> monitor sees the new service"
echo "netns_faults: PASS (3 faults; logs in $work)"
