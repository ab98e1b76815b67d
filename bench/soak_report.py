#!/usr/bin/env python3
"""Summary and verdict of a soak run (bench/soak.sh), from the files it leaves in its work directory.

    bench/soak_report.py WORK_DIR FUSION_EXIT_STATUS MINUTES RATE_HZ

Memory: the service's RSS is a sawtooth, not a ramp. Cyclone's receive buffer (Sizing/
ReceiveBufferSize, 1 MiB by default, one per receive thread) is filled front to back and replaced by a
fresh one when full, so resident memory climbs by up to about 1 MB over tens of minutes and drops back
(the 1 MiB + 4 kB anonymous mappings in smaps_*.txt). A leak raises the troughs; a buffer does not.
Growth is therefore measured on the lower envelope: the lowest RSS of the last third of the run minus
the lowest of the first third (after the first minute), scaled to one hour. The raw series is in
rss.csv.
"""
import csv
import json
import re
import sys


def main() -> int:
    work, fusion_rc, minutes, rate = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
    stream = [json.loads(line) for line in open(f"{work}/stream.jsonl") if line.strip()]
    stream = [r for r in stream if r.get("type") == "health" and "counters" in r]
    # Health stamped with the last epoch already reports the simulator's exit (gyros absent): judge the
    # run on the Health before it.
    running = None
    if stream:
        last_t = max(r["time_s"] for r in stream)
        stream = [r for r in stream if r["time_s"] < last_t]
        running = stream[-1] if stream else None
    modes = {}
    for r in stream:
        modes[r["mode"]] = modes.get(r["mode"], 0) + 1
    sim = open(f"{work}/sim.out").read()
    published = int(re.search(r"epochs published: (\d+)", sim).group(1))
    health, events = None, []
    for line in open(f"{work}/health.jsonl"):
        r = json.loads(line)
        if r.get("type") == "health":
            health = r
        elif r.get("type") == "event":
            events.append(r)
    if health is None or "counters" not in health:
        print("soak: FAIL: no Health from the service")
        return 1
    c = health["counters"]
    rows = [(int(r["time_s"]), int(r["rss_kB"]), float(r["cpu_s"]), float(r.get("steal_s") or 0))
            for r in csv.DictReader(open(f"{work}/rss.csv"))]
    after_warmup = [r for r in rows if r[0] >= 60] or rows
    span = after_warmup[-1][0] - after_warmup[0][0]
    first = [r for r in after_warmup if r[0] <= after_warmup[0][0] + span / 3]
    last = [r for r in after_warmup if r[0] >= after_warmup[-1][0] - span / 3]
    trough_first, trough_last = min(first, key=lambda r: r[1]), min(last, key=lambda r: r[1])
    dt_h = max(1, trough_last[0] - trough_first[0]) / 3600.0
    growth_kB = trough_last[1] - trough_first[1]
    growth_per_hour_kB = growth_kB / dt_h if trough_last[0] > trough_first[0] else 0.0
    rss_max, rss_min = max(r[1] for r in after_warmup), min(r[1] for r in after_warmup)
    cpu_share = 100.0 * (rows[-1][2] - rows[0][2]) / max(1, rows[-1][0] - rows[0][0])
    # Counters as of the simulator's end: the final Health minus what the end itself causes (gyros absent).
    cr = running["counters"] if running else c
    ignored = ("epochs_accepted", "samples_accepted")
    anomalies = {k: v for k, v in cr.items() if k not in ignored and v != 0}
    lost = published - c["epochs_accepted"]
    print(f"soak: {minutes:g} min at {rate:g} Hz")
    print(f"  epochs published {published}, accepted {c['epochs_accepted']}, lost {lost}")
    print(f"  samples accepted {c['samples_accepted']} (4 per epoch: {4 * published})")
    print(f"  counters not zero while the simulator ran: {anomalies if anomalies else 'none'}")
    after = {k: v for k, v in c.items() if k not in ignored and v != 0}
    print(f"  counters not zero after it stopped: {after}")
    print(f"  Health modes seen twice a second during the run: {modes}")
    print(f"  events: {len(events)} (events_published {health.get('events_published')}); mode at the end of the "
          f"data {running['mode'] if running else '?'}, after it {health['mode']}")
    print(f"  RSS after the first minute: {after_warmup[0][1]} kB at {after_warmup[0][0]} s, {rows[-1][1]} kB at "
          f"{rows[-1][0]} s; min {rss_min} kB, max {rss_max} kB (receive-buffer sawtooth {rss_max - rss_min} kB)")
    print(f"  RSS lower envelope: {trough_first[1]} kB at {trough_first[0]} s, {trough_last[1]} kB at "
          f"{trough_last[0]} s: growth {growth_kB} kB, {growth_per_hour_kB:.0f} kB per hour")
    print(f"  service CPU {cpu_share:.1f} % of one core; exit status on SIGTERM {fusion_rc}")
    if rows[-1][3] > 0:
        print(f"  steal time (the hypervisor's, both CPUs) during the run: {rows[-1][3] - rows[0][3]:.2f} s")
    # When a gyro was declared absent: the service's own log, to set beside load and steal time.
    silent = [line.split("]")[0].strip("[")[:8] for line in open(f"{work}/fusion.log") if "silent for" in line]
    if silent:
        print(f"  gyros declared silent at (wall clock): {sorted(set(silent))}")
    ok = (lost == 0 and not anomalies and not events and growth_per_hour_kB < 1024 and fusion_rc == 0
          and running is not None and running["mode"] == "NOMINAL")
    print("soak: PASS" if ok else "soak: FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
