#!/usr/bin/env python3
"""The measured figures the docs quote, recomputed: each group prints the table its doc shows.

    bench/doc_figures.py [--tetra build/tetra] [--source .] [--check] [--plot] GROUP...

GROUP:
  seed         the seed's attitude experiment (README.md's table and tour, docs/score.md): turntable ->
               calibrate -> lab-orbit -> replay (own calibration, factory calibration) -> score
  closed-loop  docs/sim.md's closed-loop table and the stuck/ramp variants
               (examples/sim/closed_loop_nadir.yaml; --plot rewrites docs/closed_loop_exclusion.png)
  lab-truth    docs/sim.md's "What to expect downstream": replay of lab-orbit --seed 2 with the truth calibration
  allan        docs/allan.md's example (two hours of the simulated unit at rest, 100 Hz)
  demo-length  the length of `tetra demo` from its defaults (simulated seconds / speed), as the docs quote it
  demo         the length of `tetra demo` measured (wall clock, so never --check'ed)

--check compares each figure with the number the doc prints (the doc's text is searched with a pattern
that must match exactly once) within the tolerance given beside it, and exits 1 on any difference. Every
run is seeded, so the figures are reproducible; the tolerances only allow for the doc's rounding and for
the last digits another compiler or libm may change.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

ARGS = None


def tetra(*args, cwd):
    r = subprocess.run([ARGS.tetra, *args], cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"tetra {' '.join(args)}: exit {r.returncode}\n{r.stderr}")
    return r.stdout + r.stderr


def num(pattern, text):
    m = re.search(pattern, text)
    if not m:
        sys.exit(f"pattern not found in the output: {pattern}\n{text}")
    return float(m.group(1))


# --- seed experiment ---------------------------------------------------------------------------------

def seed(d):
    src = ARGS.source
    tetra("sim", "turntable", "-o", "tt.csv", cwd=d)
    tetra("calibrate", "tt.csv", "-o", "cal.yaml", cwd=d)
    tetra("sim", "lab-orbit", "-o", "lab.csv", "--truth", "lab_truth.csv", cwd=d)
    f = {}
    for name, cal in (("cal", "cal.yaml"), ("factory", os.path.join(src, "examples/factory.yaml"))):
        tetra("replay", "lab.csv", "--calibration", cal, "--latitude", "-23.2", "--attitude", f"att_{name}.csv",
              "--events", f"ev_{name}.jsonl", cwd=d)
        out = tetra("score", f"att_{name}.csv", "lab_truth.csv", "--axis", "y", cwd=d)
        f[f"angle_{name}"] = num(r"integrated angle about y: ([-\d.]+) deg", out)
        if name == "cal":
            f["final_total"] = num(r"final\s+\S+\s+\S+\s+\S+\s+([\d.e+-]+)", out)
            rms = re.search(r"RMS\s+([\d.e+-]+)\s+([\d.e+-]+)\s+([\d.e+-]+)\s+([\d.e+-]+)", out)
            f["rms_x"], f["rms_y"], f["rms_z"], f["rms_total"] = (float(v) for v in rms.groups())
            f["nees"] = num(r"NEES, 3 dof \(expectation 3\): mean ([\d.]+)", out)
            f["within1_y"] = num(r"within 1/2/3 sigma, y: ([\d.]+)", out)
            sig = [line.split(",") for line in open(os.path.join(d, "att_cal.csv")) if line[0].isdigit()]
            f["sigma_axis_last"] = max(float(v) for v in sig[-1][11:14])  # sigma_x_deg, _y_, _z_
            f["sigma_axis_max"] = max(float(v) for r in sig for v in r[11:14])
    ratios = [f["sigma_axis_last"] / f[k] for k in ("rms_x", "rms_y", "rms_z")]
    f["ratio_min"], f["ratio_max"] = min(ratios), max(ratios)
    print("| calibration | integrated angle | seed paper |\n|---|---|---|")
    print(f"| `examples/factory.yaml` | {f['angle_factory']:.1f}° | 467° |")
    print(f"| made by `tetra calibrate` | {f['angle_cal']:.2f}° | 362° |")
    print(f"own calibration: final error {f['final_total']:.4f}°, RMS {f['rms_total']:.4f}° "
          f"(x {f['rms_x']:.4f}, y {f['rms_y']:.4f}, z {f['rms_z']:.4f}°); sigma per axis at most "
          f"{f['sigma_axis_max']:.3f}°, {f['ratio_min']:.0f}-{f['ratio_max']:.0f} times the RMS error; "
          f"NEES {f['nees']:.3f}; within 1 sigma (y) {f['within1_y']:.1f} %")
    return f


SEED_CHECKS = [
    # (doc, pattern with one number, figure, tolerance, why this tolerance)
    ("README.md", r"\| ([\d.]+)° \| 362° \|", "angle_cal", 0.01, "printed to 0.01°"),
    ("README.md", r"\| ([\d.]+)° \| 467° \|", "angle_factory", 0.05, "printed to 0.1°"),
    ("README.md", r"# integrated angle about y: ([\d.]+) deg", "angle_cal", 0.01, "printed to 0.01°"),
    ("docs/score.md", r"`integrated angle about y: ([\d.]+) deg", "angle_cal", 0.01, "printed to 0.01°"),
    ("docs/score.md", r"instead the same command prints ([\d.]+)°", "angle_factory", 0.05, "printed to 0.1°"),
    ("docs/score.md", r"ends\s+([\d.]+)° from the truth", "final_total", 0.00006, "printed to 0.0001°"),
    ("docs/score.md", r"\(RMS ([\d.]+)°;", "rms_total", 0.00006, "printed to 0.0001°"),
    ("docs/score.md", r"stays\s+at ([\d.]+)° per axis", "sigma_axis_max", 0.0006, "printed to 0.001°"),
    ("docs/score.md", r"NEES ([\d.]+) on average", "nees", 0.0006, "printed to 0.001"),
    ("docs/score.md", r"pessimistic, (\d+)[–-]\d+ times", "ratio_min", 0.6, "printed to 1"),
    ("docs/score.md", r"pessimistic, \d+[–-](\d+) times", "ratio_max", 0.6, "printed to 1"),
]


# --- closed loop ---------------------------------------------------------------------------------------

def closed_loop(d):
    y = "examples/sim/closed_loop_nadir.yaml"  # relative: the plot's title shows it
    f = {}

    def run(tag, *extra):
        out = tetra("sim", y, "--closed-loop", "--compare-exclusion", *extra, cwd=ARGS.source)
        for who, key in (("with exclusion", "on"), ("without exclusion", "off")):
            seg = re.findall(who + r":   (.+?) \[[\d.]+, [\d.]+\) s: rms ([\d.]+) deg, max ([\d.]+) deg,? ?(.*)", out)
            f[f"{tag}_{key}_before_rms"], f[f"{tag}_{key}_before_max"] = float(seg[0][1]), float(seg[0][2])
            f[f"{tag}_{key}_after_rms"], f[f"{tag}_{key}_after_max"] = float(seg[1][1]), float(seg[1][2])
            f[f"{tag}_{key}_recovered"] = not seg[1][3].startswith("NOT")
            f[f"{tag}_{key}_isolation"] = num(who + r": fdi: \w+, detection [\d.]+ s, isolation ([\d.]+) s", out)
        return out

    plot = ["--plot", "docs/closed_loop_exclusion.png"] if ARGS.plot else []
    run("bias", *plot)
    run("noref", "--reference-hz", "0")
    run("stuck", "--fault", "gyro=3,kind=stuck,at=1800")
    run("ramp", "--fault", "gyro=4,kind=ramp,at=1800,size=1e-4")
    print("| | before the fault: rms / max | after: rms / max | recovered | FDI |\n|---|---|---|---|---|")
    for tag, title in (("bias", ""), ("noref", " (no star tracker)")):
        for key, who in (("on", "with exclusion"), ("off", "exclusion disabled")):
            p = f"{tag}_{key}_"
            print(f"| {who}{title} | {f[p + 'before_rms']:.2g}° / {f[p + 'before_max']:.2g}° | "
                  f"{f[p + 'after_rms']:.2g}° / {f[p + 'after_max']:.2g}° | "
                  f"{'yes' if f[p + 'recovered'] else 'no'} | isolated {f[p + 'isolation']:.1f} s after |")
    for tag in ("stuck", "ramp"):
        print(f"{tag}: after the fault max {f[tag + '_on_after_max']:.2g}° with exclusion, "
              f"{f[tag + '_off_after_max']:.3g}° without")
    return f


CLOSED_LOOP_CHECKS = [  # relative tolerances
    # Printed to 2 significant digits: 6 % relative covers the rounding of the smallest (0.0011 ± 0.00005).
    ("docs/sim.md", r"\| with exclusion \| ([\d.]+)° / [\d.]+° \(the initial", "bias_on_before_rms", 0.06, "2 digits"),
    ("docs/sim.md", r"\| with exclusion \| [\d.]+° / ([\d.]+)° \(the initial", "bias_on_before_max", 0.06, "2 digits"),
    ("docs/sim.md", r"\| with exclusion \| [^|]+\| ([\d.]+)° / [\d.]+° \|", "bias_on_after_rms", 0.06, "2 digits"),
    ("docs/sim.md", r"\| with exclusion \| [^|]+\| [\d.]+° / ([\d.]+)° \|", "bias_on_after_max", 0.06, "2 digits"),
    ("docs/sim.md", r"\| exclusion disabled \| [^|]+\| ([\d.]+)° / [\d.]+° \|", "bias_off_after_rms", 0.06, "2 digits"),
    ("docs/sim.md", r"\| exclusion disabled \| [^|]+\| [\d.]+° / ([\d.]+)° \|", "bias_off_after_max", 0.06, "2 digits"),
    ("docs/sim.md", r"fault ([\d.]+)° / [\d.]+° \(rms / max\) with exclusion", "noref_on_after_rms", 0.06, "2 digits"),
    ("docs/sim.md", r"fault [\d.]+° / ([\d.]+)° \(rms / max\) with exclusion", "noref_on_after_max", 0.06, "2 digits"),
    ("docs/sim.md", r"with exclusion, ([\d.]+)° / [\d.]+° and not recovered", "noref_off_after_rms", 0.06, "2 digits"),
    ("docs/sim.md", r"with exclusion, [\d.]+° / ([\d.]+)° and not recovered", "noref_off_after_max", 0.06, "2 digits"),
    ("docs/sim.md", r"Stuck gyro 3 at\s+1800 s: ([\d.]+)° max with exclusion", "stuck_on_after_max", 0.06, "2 digits"),
    ("docs/sim.md", r"max with exclusion, ([\d.]+)° without", "stuck_off_after_max", 0.06, "2 digits"),
    ("docs/sim.md", r"on gyro 4: ([\d.]+)°\s+against", "ramp_on_after_max", 0.06, "2 digits"),
    ("docs/sim.md", r"on gyro 4: [\d.]+°\s+against ([\d.]+)°", "ramp_off_after_max", 0.06, "2 digits"),
]


# --- replay with the truth calibration (docs/sim.md, "What to expect downstream") ----------------------

def lab_truth(d):
    tetra("sim", "lab-orbit", "--seed", "2", "-o", "lab2.csv", "--truth", "lab2_truth.csv", cwd=d)
    tetra("sim", "--write-unit", "truth_cal.yaml", cwd=d)  # the simulated unit itself
    out = tetra("replay", "lab2.csv", "--calibration", "truth_cal.yaml", "--latitude", "-23.2", "--attitude",
                "att_truth.csv", "--events", "ev_truth.jsonl", cwd=d)
    mode = re.search(r"final mode: (\w+)", out).group(1)
    events = sum(1 for _ in open(os.path.join(d, "ev_truth.jsonl")))
    score = tetra("score", "att_truth.csv", "lab2_truth.csv", cwd=d)
    f = {"final_total": num(r"final\s+\S+\s+\S+\s+\S+\s+([\d.e+-]+)", score), "events": events}
    print(f"lab-orbit --seed 2, truth calibration: final error {f['final_total']:.5f}°, mode {mode}, {events} events")
    if mode != "NOMINAL" or events:
        sys.exit("docs/sim.md says mode NOMINAL and no events")
    return f


LAB_TRUTH_CHECKS = [
    ("docs/sim.md", r"calibration ends\s+([\d.]+)° from the truth attitude", "final_total", 0.000006,
     "printed to 0.00001°"),
]


def allan(d):
    tetra("sim", "static", "--rate-hz", "100", "--minutes", "120", "-o", "static_2h.csv", cwd=d)
    tetra("sim", "--write-unit", "cal.yaml", cwd=d)
    out = tetra("allan", "static_2h.csv", "--calibration", "cal.yaml", cwd=d)
    rows = re.findall(r"^([1-4])\s+NO\s+([\d.e+-]+)\s+([\d.e+-]+)\s+NO", out, re.M)[:4]
    f = {f"{k}{g}": float(v) for g, n, b in rows for k, v in (("N", n), ("B", b))}
    f["B_min"], f["B_max"] = min(f[f"B{g}"] for g in "1234"), max(f[f"B{g}"] for g in "1234")
    print("gyro  N [deg/√s]  B [deg/s]")
    for g in "1234":
        print(f"{g}     {f['N' + g]:.2e}    {f['B' + g]:.2e}")
    return f


ALLAN_CHECKS = [  # printed to 3 digits: 0.2 % relative
    ("docs/allan.md", r"R \[deg/s²\]\n1     NO              ([\d.e+-]+)        [\d.e+-]+        NO", "N1", 0.002, "3 digits"),
    ("docs/allan.md", r"R \[deg/s²\]\n1     NO              [\d.e+-]+        ([\d.e+-]+)        NO", "B1", 0.002, "3 digits"),
    ("docs/allan.md", r"B \(([\d.]+)[–-][\d.]+e-6 deg/s over", "B_min", 0.02, "2 digits, in units of 1e-6"),
]


def demo_length(d):
    """The demo's length from its defaults (simulated seconds / speed): what the docs quote, not timed."""
    out = tetra("demo", "--help", cwd=d)
    seconds = num(r"--seconds [^=\n]*=([\d.]+)", out)
    speed = num(r"--speed [^=\n]*=([\d.]+)", out)
    print(f"tetra demo: {seconds:g} simulated s at {speed:g}x real time: {seconds / speed:g} s of wall clock")
    return {"demo_s": seconds / speed, "demo_sim_s": seconds, "demo_speed": speed}


DEMO_CHECKS = [  # the docs round to whole seconds; the measured run adds ~0.5 s of start-up and summary
    ("README.md", r"then the demo's\s+(\d+) s:", "demo_s", 0.5, "whole seconds"),
    ("README.md", r"s: (\d+) simulated seconds", "demo_sim_s", 0.5, "whole seconds"),
    ("docs/dds.md", r"everything below in ~(\d+) s", "demo_s", 0.5, "whole seconds"),
]


def demo(d):
    start = time.monotonic()
    tetra("demo", cwd=d)
    seconds = time.monotonic() - start
    print(f"tetra demo: {seconds:.1f} s")
    return {"demo_s": seconds}


def check(figures, checks, relative):
    bad = 0
    for doc, pattern, key, tol, why in checks:
        text = open(os.path.join(ARGS.source, doc), encoding="utf-8").read()
        found = re.findall(pattern, text)
        if len(found) != 1:
            print(f"FAIL {doc}: pattern {pattern!r} matches {len(found)} times (expected once)")
            bad += 1
            continue
        doc_value, value = float(found[0]), figures[key]
        limit = tol * abs(value) if relative else tol
        ok = abs(doc_value - value) <= limit
        bad += not ok
        print(f"{'ok  ' if ok else 'FAIL'} {doc}: {key} doc {doc_value:g}, measured {value:.6g} "
              f"(tolerance {'±%g %%' % (tol * 100) if relative else '±%g' % tol}: {why})")
    return bad


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetra", default="build/tetra")
    ap.add_argument("--source", default=".")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--plot", action="store_true", help="closed-loop: rewrite docs/closed_loop_exclusion.png")
    ap.add_argument("groups", nargs="+", choices=["seed", "closed-loop", "lab-truth", "allan", "demo-length", "demo"])
    ARGS = ap.parse_args()
    ARGS.tetra = os.path.abspath(ARGS.tetra)
    ARGS.source = os.path.abspath(ARGS.source)
    bad = 0
    with tempfile.TemporaryDirectory(prefix="tetra-figures-") as d:
        for g in ARGS.groups:
            print(f"## {g}")
            if g == "seed":
                f = seed(d)
                bad += check(f, SEED_CHECKS, False) if ARGS.check else 0
            elif g == "closed-loop":
                f = closed_loop(d)
                bad += check(f, CLOSED_LOOP_CHECKS, True) if ARGS.check else 0
            elif g == "lab-truth":
                f = lab_truth(d)
                bad += check(f, LAB_TRUTH_CHECKS, False) if ARGS.check else 0
            elif g == "allan":
                f = allan(d)
                f["B_min"] *= 1e6
                bad += check(f, ALLAN_CHECKS, True) if ARGS.check else 0
            elif g == "demo-length":
                f = demo_length(d)
                bad += check(f, DEMO_CHECKS, False) if ARGS.check else 0
            else:
                demo(d)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
