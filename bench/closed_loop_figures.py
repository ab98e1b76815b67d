#!/usr/bin/env python3
"""The closed loop's measured figures in docs/campaign.md and docs/sim.md, recomputed; each group prints what its
doc shows (docs/sim.md's closed-loop table and docs/closed_loop_exclusion.png: bench/doc_figures.py closed-loop).

    bench/closed_loop_figures.py [--tetra build/tetra] [--source .] [--domain 57] [--check] GROUP...

GROUP:
  campaign      examples/campaign.yaml in process (520 runs, about a minute on 2 cores): the pointing after
                the fault (median, 99 %, max of each run's max), within the bound, recovered, wrong exclusions
  campaign-dds  examples/campaign_dds.yaml over DDS on --domain (26 runs, one `tetra fusion` per run): wall
                time, max pointing error after the fault, and whether its rows equal the in-process rows
  lockstep      `tetra sim --closed-loop --dds` in lockstep against one `tetra fusion` on --domain: a 10 Hz
                loop with a 1 Hz reference for 600 s (6000 epochs): epochs per second of wall clock, and
                whether the pointing CSV equals the in-process loop's byte for byte

--check compares the deterministic figures (pointing, counts) with the numbers the docs print (tolerances as
in doc_figures.py); wall-clock figures are printed, never checked.
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile
import time

import doc_figures as figures


def quantile(values, q):
    """The report's quantile (sim/src/campaign_report.cpp): nearest rank on the sorted values."""
    v = sorted(values)
    return v[min(int(q * (len(v) - 1) + 0.5), len(v) - 1)]


def rows_of(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def pointing(rows):
    faulty = [r for r in rows if r["kind"] != "none" and r["pointing_max_after_deg"] not in ("", "nan")]
    after = [float(r["pointing_max_after_deg"]) for r in faulty]
    return {
        "runs": len(rows), "faulty": len(faulty),
        "median": quantile(after, 0.5), "p99": quantile(after, 0.99), "max": max(after),
        "within": sum(float(r["pointing_max_after_deg"]) < float(r["bound_deg"]) for r in faulty),
        "recovered": sum(r["recover_s"] != "" for r in rows),
        "wrong": sum(r["outcome"] == "wrong" for r in rows),
    }


def campaign(d):
    start = time.monotonic()
    figures.tetra("campaign", os.path.join(ARGS.source, "examples/campaign.yaml"), "--out", "local", cwd=d)
    wall = time.monotonic() - start
    f = pointing(rows_of(os.path.join(d, "local/runs.csv")))
    print(f"{f['runs']} runs in {wall:.0f} s wall; max pointing error after the fault: median {f['median']:.2g}°, "
          f"99 % {f['p99']:.2g}°, max {f['max']:.2g}°; within the bound {f['within']} of {f['faulty']}; "
          f"recovered {f['recovered']} of {f['runs']}; wrong exclusions {f['wrong']}")
    return f


CAMPAIGN_CHECKS = [  # printed to 2 significant digits: 6 % relative (as doc_figures.py's closed loop)
    ("docs/campaign.md", r"bound \(median ([\d.]+)°, 99 % [\d.]+°, max [\d.]+°\)", "median", 0.06, "2 digits"),
    ("docs/campaign.md", r"bound \(median [\d.]+°, 99 % ([\d.]+)°, max [\d.]+°\)", "p99", 0.06, "2 digits"),
    ("docs/campaign.md", r"bound \(median [\d.]+°, 99 % [\d.]+°, max ([\d.]+)°\)", "max", 0.06, "2 digits"),
]


def campaign_dds(d):
    spec = os.path.join(ARGS.source, "examples/campaign_dds.yaml")
    start = time.monotonic()
    figures.tetra("campaign", spec, "--out", "dds", "--domain", str(ARGS.domain), cwd=d)
    wall = time.monotonic() - start
    # The same spec in process: a copy (and its scenario) without `target: dds` and `domain:`.
    os.makedirs(os.path.join(d, "sim"), exist_ok=True)
    with open(os.path.join(ARGS.source, "examples/sim/closed_loop_nadir.yaml")) as src:
        open(os.path.join(d, "sim/closed_loop_nadir.yaml"), "w").write(src.read())
    with open(spec) as src, open(os.path.join(d, "local.yaml"), "w") as dst:
        dst.writelines(line for line in src if not line.startswith(("target:", "domain:")))
    figures.tetra("campaign", "local.yaml", "--out", "dds_local", cwd=d)
    wire, local = rows_of(os.path.join(d, "dds/runs.csv")), rows_of(os.path.join(d, "dds_local/runs.csv"))
    f = pointing(wire)
    by_run = lambda rows: sorted(rows, key=lambda r: int(r["run"]))  # the workers finish in any order
    f["wall_s"], f["equal"] = wall, by_run(wire) == by_run(local)
    print(f"{f['runs']} runs over DDS in {wall:.0f} s wall; max pointing error after the fault {f['max']:.2g}°; "
          f"rows {'equal' if f['equal'] else 'DIFFERENT from'} the in-process rows")
    return f


CAMPAIGN_DDS_CHECKS = [
    ("docs/campaign.md", r"max pointing error after the fault ([\d.]+)°; its rows equal", "max", 0.06, "2 digits"),
]


def lockstep(d):
    figures.tetra("sim", "--write-unit", "cal.yaml", cwd=d)
    unit = f"lockstep-{os.getpid()}"
    text = re.sub(r"^unit: .*$", f"unit: {unit}", open(os.path.join(d, "cal.yaml")).read(), count=1, flags=re.M)
    open(os.path.join(d, "cal.yaml"), "w").write(text)
    with open(os.path.join(d, "loop.yaml"), "w") as f:
        f.write("scenario: orbit\nduration_s: 600\nrate_hz: 10\nunit: cal.yaml\n"
                "reference: {rate_hz: 1, noise_arcsec: 5}\nfaults: [\"gyro=2,kind=bias,at=300,size=0.01\"]\n"
                "closed_loop: {controller: {bandwidth_hz: 0.05}, pointing: {mode: nadir}, pointing_bound_deg: 0.05}\n")
    with open(os.path.join(d, "fusion.yaml"), "w") as f:
        f.write(f"unit: {unit}\ncalibration: cal.yaml\nsample_rate_hz: 10\nspeed: 1\nmax_latency_s: 0.5\n")
    figures.tetra("sim", "loop.yaml", "--closed-loop", "--pointing", "local.csv", cwd=d)
    with open(os.path.join(d, "fusion.log"), "w") as log:
        service = subprocess.Popen([ARGS.tetra, "fusion", "--config", "fusion.yaml", "--domain", str(ARGS.domain)],
                                   cwd=d, stdout=log, stderr=log)
    try:
        out = figures.tetra("sim", "loop.yaml", "--closed-loop", "--dds", "--domain", str(ARGS.domain),
                            "--pointing", "wire.csv", cwd=d)
    finally:
        service.terminate()
        service.wait()
    run_s = figures.num(r"run ([\d.]+) s", out)
    equal = open(os.path.join(d, "local.csv")).read() == open(os.path.join(d, "wire.csv")).read()
    print(f"lockstep, 6000 epochs (10 Hz, 1 Hz reference): {run_s:.2f} s, {6000 / run_s:.0f} epochs/s; "
          f"pointing CSV {'byte-identical to' if equal else 'DIFFERENT from'} the in-process loop; "
          f"load average {open('/proc/loadavg').read().split()[0]}")
    return {"epochs_per_s": 6000 / run_s, "equal": equal}


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetra", default="build/tetra")
    ap.add_argument("--source", default=".")
    ap.add_argument("--domain", type=int, default=57, help="DDS domain of the campaign-dds and lockstep groups")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("groups", nargs="+", choices=["campaign", "campaign-dds", "lockstep"])
    ARGS = ap.parse_args()
    ARGS.tetra = os.path.abspath(ARGS.tetra)
    ARGS.source = os.path.abspath(ARGS.source)
    figures.ARGS = ARGS
    bad = 0
    with tempfile.TemporaryDirectory(prefix="tetra-closed-loop-") as d:
        for g in ARGS.groups:
            print(f"## {g}")
            if g == "campaign":
                f = campaign(d)
                bad += figures.check(f, CAMPAIGN_CHECKS, True) if ARGS.check else 0
            elif g == "campaign-dds":
                f = campaign_dds(d)
                bad += (not f["equal"]) + (figures.check(f, CAMPAIGN_DDS_CHECKS, True) if ARGS.check else 0)
            else:
                bad += not lockstep(d)["equal"]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
