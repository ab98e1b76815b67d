#!/usr/bin/env bash
# Multi-host faults: simulator, fusion service and monitor each in its own network
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

now_ms() { echo $(($(date +%s%N) / 1000000)); }
t0=$(now_ms)
log() { local ms=$(($(now_ms) - t0)); printf '[%4d.%01d s] %s\n' $((ms / 1000)) $((ms % 1000 / 100)) "$*"; }
fail() { echo "netns_faults: FAIL: $*" >&2; exit 1; }

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
log "namespaces $ns_sim $ns_fus $ns_mon over bridge in $ns_hub"
link() { ip -n "$ns_hub" link set "${tag}$1h" "$2"; log "link $1 $2"; }
in_ns() {  # host, command... — run in the background (`in_ns ... &`): exec keeps $! the program's pid
  local host=$1
  shift
  exec ip netns exec "${tag}${host}" env CYCLONEDDS_URI="file://$work/cyclone-$host.xml" "$@"
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
# Timeline in seconds after the simulator starts (simulated time = wall time, speed 1):
#   5-9 sensor link down | 12-20 monitor link down, gyro 2 stuck from 14 | 30 service killed, 31 restarted
ts=$(now_ms)
in_ns sim "$tetra" sim orbit --dds --dds-unit netns-1 --domain $domain --rate-hz $rate --minutes 0.65 \
  --reference-hz 0 --fault gyro=2,kind=stuck,at=14 --wait-timeout 20 >"$work/sim.log" 2>&1 &
sim_pid=$!
pids+=("$sim_pid")
at() {  # sleep until $1 seconds after the simulator started
  local left=$((ts + $1 * 1000 - $(now_ms)))
  if [ "$left" -gt 0 ]; then sleep "$((left / 1000)).$(printf '%03d' $((left % 1000)))"; fi
}
lines() { wc -l <"$work/monitor.jsonl"; }
since() { sed -n "$(($1 + 1)),\$p" "$work/monitor.jsonl"; }  # monitor lines after line $1
# seen_since LINE PATTERN: PATTERN in the monitor's output after LINE (through a file: with pipefail,
# `sed | grep -q` fails when grep stops reading early).
seen_since() { since "$1" >"$work/window.jsonl"; grep -q -- "$2" "$work/window.jsonl"; }

at 4
grep -q '"mode": "NOMINAL"' "$work/monitor.jsonl" || fail "the service did not reach NOMINAL within 4 s"
log "service NOMINAL"
at 5
n_cut=$(lines)
link sim down
at 9
seen_since "$n_cut" '"mode": "LOST"' || fail "sensor link cut: the monitor never saw LOST"
log "check: sensor link cut -> LOST"
n_up=$(lines)
link sim up
at 11
seen_since "$n_up" '"mode": "NOMINAL"' || fail "sensor link restored: the monitor never saw NOMINAL again"
log "check: sensor link restored -> NOMINAL"

at 12
link mon down
n_mon=$(lines)
at 20
link mon up
# Reliable retransmission resumes with the writers' next heartbeats: allow it a few seconds.
for _ in $(seq 40); do
  seen_since "$n_mon" '"event": "isolated", "gyro": 2' && break
  sleep 0.2
done
seen_since "$n_mon" '"event": "isolated", "gyro": 2' ||
  fail "monitor link cut: the isolation of gyro 2 (stuck from 14 s) did not reach the monitor after reconnect"
log "check: monitor reconnected -> caught up with the isolation of gyro 2"

at 30
kill -9 "$fusion_pid"
log "service killed (SIGKILL)"
at 31
n_restart=$(lines)
start_fusion
log "service restarted"
at 37
kill -9 "$fusion_pid" 2>/dev/null || true
wait "$sim_pid" 2>/dev/null || true
# A new service starts its counters at zero: after the restart the monitor shows a Health with fewer
# accepted epochs than the old service's last, and then growing.
accepted() { grep -o '"type": "health".*"epochs_accepted": [0-9]*' | grep -o '[0-9]*$'; }
last_old=$(head -n "$n_restart" "$work/monitor.jsonl" | accepted | tail -1)
[ -n "$last_old" ] || fail "service restart: no Health of the old service"
first_new=$(since "$n_restart" | accepted | awk -v old="$last_old" '$1 < old && !found {print; found = 1}')
[ -n "$first_new" ] || fail "service restart: no Health with fresh counters (old service's last: $last_old epochs)"
last_new=$(since "$n_restart" | accepted | tail -1)
[ "$last_new" -gt "$first_new" ] || fail "service restart: the new service's counters never grew ($first_new)"
log "check: service restart -> new service seen ($last_old epochs before, then $first_new, then $last_new)"
echo "netns_faults: PASS (3 faults; logs in $work)"
