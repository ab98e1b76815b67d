#!/usr/bin/env python3
"""The DDS examples between real processes (examples/dds/, docs/dds.md "Your own subscriber"):

Python (examples/dds/python_bridge.py) publishes a simulated orbit's gyro epochs through `tetra ingest` in real
time, a separate star-tracker process (examples/dds/star_tracker, C) publishes the truth with 5 arcsec noise at
10 Hz, each sample 50-300 ms after the sensor time it was taken at (of the unit's clock as the attitudes show
it), and the C subscriber (examples/dds/attitude_subscriber) hands every Attitude, Health and FdiEvent of the
service back to Python. Run twice: with the default fusion horizon (0.5 s) every late reference is fused at its
own time and the attitude follows the truth with an honest sigma; with `reference_horizon_s: 0` every one is too
late, counted in Health and reported by one `reference_late` event, and the attitude is the gyros' alone (the
service starts 0.5 deg off the truth, which only the references can tell it). Prints `[ figure ]` lines; exit 0 on pass.
"""
import argparse
import csv
import json
import math
import os
import random
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time


def qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


def qexp(v):
    angle = math.sqrt(sum(x * x for x in v))
    if angle < 1e-300:
        return (1.0, 0.0, 0.0, 0.0)
    s = math.sin(angle / 2) / angle
    return (math.cos(angle / 2), v[0] * s, v[1] * s, v[2] * s)


def qlog(q):
    w, x, y, z = q
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    n = math.sqrt(x * x + y * y + z * z)
    if n < 1e-300:
        return (0.0, 0.0, 0.0)
    k = 2 * math.atan2(n, w) / n
    return (x * k, y * k, z * k)


def conj(q):
    return (q[0], -q[1], -q[2], -q[3])


ARCSEC = math.pi / 180 / 3600


def replay_differences(args, work, recording, q0, horizon_s, attitudes, from_ns):
    """`tetra replay` of the recording with the service's pipeline settings: how many of the service's attitudes
    from `from_ns` on (as the subscriber received them, every double exact) differ from replay's of the same
    epoch, of how many, and the largest angle between the two [arcsec]. The first seconds are left out: a
    recorder that discovers the tracker late (a loaded machine) misses its first samples, which set the
    service's attitude from its 0.5 deg start (1,800 arcsec until the next sample reaches the recording)."""
    config = os.path.join(work, "pipeline.yaml")
    with open(config, "w") as f:
        f.write("pipeline:\n  initial_q_wxyz: [%.17g, %.17g, %.17g, %.17g]\n  reference_horizon_s: %g\n"
                % (*q0, horizon_s))
    out = os.path.join(work, "replay_att.csv")
    run = subprocess.run([args.tetra, "replay", recording, "--calibration",
                          os.path.join(args.source, "examples", "seed_unit.yaml"), "--config", config, "--attitude",
                          out, "--events", os.path.join(work, "replay_events.jsonl")], capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError("tetra replay of the recording: exit %d\n%s" % (run.returncode, run.stderr))
    rows = list(csv.reader(line for line in open(out) if not line.startswith("#")))
    replayed = {round(float(r[0]) * 1e9): tuple(float(v) for v in r[1:5]) for r in rows[1:]}
    pairs = [(tuple(a["q_RB"]), replayed[a["stamp_ns"]]) for a in attitudes
             if a["stamp_ns"] in replayed and a["stamp_ns"] >= from_ns]
    apart = [math.sqrt(sum(x * x for x in qlog(qmul(conj(mine), theirs)))) / ARCSEC for mine, theirs in pairs]
    return sum(1 for mine, theirs in pairs if mine != theirs), len(pairs), max(apart)


def run_case(args, horizon_s, domain, work):
    sys.path.insert(0, os.path.join(args.source, "examples", "dds"))
    import python_bridge as bridge

    log, truth_path = os.path.join(work, "log.csv"), os.path.join(work, "truth.csv")
    subprocess.run([args.tetra, "sim", "orbit", "--seed", "3", "--minutes", str(args.seconds / 60), "--rate-hz",
                    "100", "--reference-hz", "0", "-o", log, "--truth", truth_path], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    epochs = [(float(r[0]), [float(v) for v in r[1:5]]) for r in csv.reader(
        line for line in open(log) if not line.startswith("#") and not line.startswith("time_s"))]
    truth = {}
    for r in csv.reader(line for line in open(truth_path) if not line.startswith("#")):
        if r[0] != "time_s":
            truth[round(float(r[0]) * 1e6)] = tuple(float(v) for v in r[1:5])
    # The service starts 0.5 deg off the truth: only the references can tell it (the first one sets it).
    q0 = qmul(truth[round(epochs[0][0] * 1e6)], qexp([0.5 * math.pi / 180, 0.0, 0.0]))
    config = os.path.join(work, "fusion.yaml")
    with open(config, "w") as f:
        f.write("unit: tetra-py\ncalibration: %s\nsample_rate_hz: 100\nspeed: 1\nhealth_period_s: 0.5\n"
                "pipeline:\n  initial_q_wxyz: [%.17g, %.17g, %.17g, %.17g]\n  reference_horizon_s: %g\n"
                % (os.path.join(args.source, "examples", "seed_unit.yaml"), *q0, horizon_s))
    fusion_log = open(os.path.join(work, "fusion.log"), "w")
    fusion = subprocess.Popen([args.tetra, "fusion", "--config", config, "--domain", str(domain)],
                              stdout=fusion_log, stderr=fusion_log)
    try:
        deadline = time.time() + 20
        while "running" not in open(os.path.join(work, "fusion.log")).read():
            if time.time() > deadline or fusion.poll() is not None:
                raise RuntimeError("fusion did not start: " + open(os.path.join(work, "fusion.log")).read())
            time.sleep(0.05)
        # A recorder of the gyro and reference streams: a reference fused late goes on the row of the epoch it
        # reached with its own time (ref_stamp_s), so replay of the recording fuses it as the service did.
        recording = os.path.join(work, "rec.csv")
        recorder = subprocess.Popen([args.tetra, "record", "--config", config, "--domain", str(domain), "-o",
                                     recording, "--until-idle"], stdout=subprocess.DEVNULL,
                                    stderr=open(os.path.join(work, "record.log"), "w"))
        sub = bridge.Subscriber(args.subscriber, "tetra-py", domain)
        received = {"attitude": [], "health": [], "event": []}
        newest = [None]

        def read():
            for m in sub:
                received[m["type"]].append(m)
                if m["type"] == "attitude":
                    newest[0] = m["stamp_ns"]
        reader = threading.Thread(target=read, daemon=True)
        reader.start()
        tracker = bridge.StarTracker(args.tracker, "tetra-py", domain)
        gyros = bridge.GyroPublisher(args.tetra, "tetra-py", domain, 4, 100)
        time.sleep(1.5)  # ingest waits for the service's reader and 200 ms of discovery before it reads
        rng = random.Random(11)
        t0 = epochs[0][0]
        refs = [t0 + 1.0 + 0.1 * k for k in range(int((epochs[-1][0] - t0 - 1.5) * 10))]
        delays = [0.05 + 0.25 * rng.random() for _ in refs]
        sent, late_s = 0, []
        start = time.monotonic()
        for t, raw in epochs:
            pause = start + (t - t0) - time.monotonic()
            if pause > 0:
                time.sleep(pause)
            gyros.send(t, raw)
            now_ns = newest[0]
            # One a 10-ms epoch at most: the tracker's samples go out one by one, never bunched.
            if sent < len(refs) and now_ns is not None and now_ns >= (refs[sent] + delays[sent]) * 1e9:
                stamp_ns = round(refs[sent] * 1e9)
                q = qmul(truth[round(refs[sent] * 1e6)], qexp([rng.gauss(0, 5 * ARCSEC) for _ in range(3)]))
                tracker.send(stamp_ns, q)
                late_s.append(now_ns / 1e9 - refs[sent])
                sent += 1
        gyros.close()
        recorder.wait(timeout=30)
        time.sleep(1.0)
        tracker.close()
        fusion.send_signal(signal.SIGTERM)
        fusion.wait(timeout=10)
        time.sleep(0.5)
        sub.close()
        reader.join(timeout=5)
    finally:
        if fusion.poll() is None:
            fusion.kill()
            fusion.wait()
    rows = [r for r in csv.reader(line for line in open(recording) if not line.startswith("#"))]
    ref_col = rows[0].index("ref_qw") if "ref_qw" in rows[0] else None
    recorded_refs = 0 if ref_col is None else sum(1 for r in rows[1:] if r[ref_col] != "")
    stamp_col = rows[0].index("ref_stamp_s") if "ref_stamp_s" in rows[0] else None
    recorded_late = 0 if stamp_col is None else sum(1 for r in rows[1:] if r[stamp_col] != "")
    settle_ns = (t0 + 5.0) * 1e9
    differing, compared, apart_arcsec = replay_differences(args, work, recording, q0, horizon_s, received["attitude"],
                                                           settle_ns)
    health = received["health"][-1]
    late_events = [e for e in received["event"] if e["event"] == "reference_late"]
    errors, nees = [], []
    for a in received["attitude"]:
        q_true = truth.get(round(a["stamp_ns"] / 1e3))
        if q_true is None or a["stamp_ns"] < settle_ns:
            continue
        e = qlog(qmul(conj(a["q_RB"]), q_true))
        errors.append(math.sqrt(sum(x * x for x in e)))
        nees.append(sum((x / s) ** 2 for x, s in zip(e, a["sigma_rad"])))
    rms = math.sqrt(sum(x * x for x in errors) / len(errors)) / ARCSEC
    out = {"horizon_s": horizon_s, "sent": sent, "late_min_s": min(late_s), "late_max_s": max(late_s),
           "delayed": health["references_delayed"], "too_late": health["references_too_late"],
           "late_events": len(late_events), "samples_late": health["samples_late"],
           "recorded_epochs": len(rows) - 1, "recorded_references": recorded_refs,
           "recorded_late_references": recorded_late, "replay_compared": compared, "replay_differing": differing,
           "replay_apart_max_arcsec": apart_arcsec,
           "replay_due": sum(1 for a in received["attitude"] if a["stamp_ns"] >= settle_ns),
           "attitudes": len(received["attitude"]), "epochs": len(epochs),
           "rms_arcsec": rms, "final_arcsec": errors[-1] / ARCSEC, "mean_nees": sum(nees) / len(nees),
           "reference_state": health["reference_state"]}
    print("[ figure ] %s" % json.dumps(out), flush=True)
    return out, late_events


def example_lengths(source):
    """docs/dds.md's "each under N lines" and the lines of each example its table names."""
    doc = open(os.path.join(source, "docs", "dds.md"), encoding="utf-8").read()
    limit = int(re.search(r"each under (\d+) lines", doc).group(1))
    names = sorted(set(re.findall(r"^\| `(examples/dds/[\w.]+\.(?:c|cpp|py))` \|", doc, re.M)))
    return limit, {n: sum(1 for _ in open(os.path.join(source, n), encoding="utf-8")) for n in names}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tetra", required=True)
    ap.add_argument("--subscriber", required=True)
    ap.add_argument("--tracker", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--domain", type=int, default=203)
    args = ap.parse_args()
    os.environ["CYCLONEDDS_URI"] = "file://" + os.path.join(args.source, "config", "cyclonedds-loopback.xml")
    failures = []

    def check(ok, what):
        if not ok:
            failures.append(what)
            print("FAIL: " + what, flush=True)

    limit, lengths = example_lengths(args.source)
    check(all(n < limit for n in lengths.values()),
          "each example under %d lines (docs/dds.md): %s" % (limit, lengths))
    with tempfile.TemporaryDirectory() as work:
        fused, _ = run_case(args, 0.5, args.domain, work)
    with tempfile.TemporaryDirectory() as work:
        dropped, events = run_case(args, 0.0, args.domain + 1, work)
    check(fused["late_min_s"] >= 0.05 and fused["late_max_s"] <= 0.35, "references sent 50-300 ms late")
    check(fused["delayed"] >= fused["sent"] - 2 and fused["too_late"] == 0, "late references fused")
    check(fused["late_events"] == 0, "no reference_late event within the horizon")
    check(fused["rms_arcsec"] < 15.0, "the attitude follows the late star tracker")
    check(0.5 * 3 <= fused["mean_nees"] <= 2.0 * 3, "sigma honest with late references (NEES)")
    check(fused["attitudes"] >= 0.95 * fused["epochs"], "an attitude per epoch")
    check(fused["recorded_epochs"] >= 0.95 * fused["epochs"], "the recorder has (nearly) every epoch")
    check(fused["recorded_late_references"] == fused["recorded_references"] >= fused["delayed"] - 2,
          "the recorder writes every reference fused late, with its own time (ref_stamp_s)")
    # The recorder's assembler may hand a late reference to another epoch than the service's did (each process
    # receives the two streams in its own order): replay fuses it at the same stamp, one epoch earlier or later
    # — or, for a recorder slow at the start, beyond the horizon, so that the first sample, which sets the
    # attitude from its 0.5 deg start, is left out until the next: compared from 5 s on (replay_differences).
    check(fused["replay_compared"] >= 0.95 * fused["replay_due"] and fused["replay_apart_max_arcsec"] < 5.0,
          "replay of the recording fuses the late references as the service did (within the tracker's 5 arcsec)")
    check(dropped["replay_compared"] >= 0.95 * dropped["replay_due"] and dropped["replay_differing"] == 0,
          "beyond the horizon: replay of the recording gives the service's attitudes bit for bit")
    check(dropped["delayed"] == 0 and dropped["too_late"] >= dropped["sent"] - 2, "beyond the horizon: counted")
    check(dropped["late_events"] == 1 and 0.05 <= events[0]["statistic"] <= 0.35, "said by one event")
    check(dropped["rms_arcsec"] > 10 * fused["rms_arcsec"], "without the horizon the reference is lost")
    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("examples: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
