#!/usr/bin/python3
"""Pipeline.run (the Python package) against `tetra replay` on the same 6-hour 100 Hz log (2.16 M epochs).

Both run the same pipeline over the same epochs in the same run of this script: `tetra replay` reading the
log file and writing its attitude CSV and events (its whole command, as a user times it), and
`tetra.Pipeline.run` over the log's arrays already in memory (reading the log is timed apart). Prints both
times and the ratio run / replay (target: at most 1.2). The log is an HDF5 file of `tetra sim static` with
a 1 Hz reference, made once into --work (reused when present).

usage: bench/python_pipeline.py [--build build] [--work /tmp/tetra-python-bench] [--hours 6]
"""
import argparse
import os
import pathlib
import subprocess
import sys
import time

here = pathlib.Path(__file__).resolve().parent


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=str(here.parent / "build"))
    ap.add_argument("--work", default="/tmp/tetra-python-bench")
    ap.add_argument("--hours", type=float, default=6.0)
    ap.add_argument("--repeat", type=int, default=2, help="runs of each (the best is kept)")
    a = ap.parse_args()
    build = pathlib.Path(a.build)
    sys.path.insert(0, str(build / "python"))
    import tetra

    work = pathlib.Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    tetra_bin = str(build / "tetra")
    log = work / f"static_{a.hours:g}h_100hz.h5"
    cal = here / "seed_as_built.yaml"
    if not log.exists():
        subprocess.run([tetra_bin, "sim", "static", "--minutes", str(a.hours * 60), "--rate-hz", "100",
                        "--reference-hz", "1", "--seed", "1", "-o", str(log)], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; log {log} "
          f"({log.stat().st_size / 1e6:.0f} MB)")

    replay_s = []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        subprocess.run([tetra_bin, "replay", str(log), "--calibration", str(cal), "--attitude",
                        str(work / "att.csv"), "--events", str(work / "events.jsonl")], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        replay_s.append(time.perf_counter() - t0)

    t0 = time.perf_counter()
    g = tetra.read_gyro_log(str(log))
    read_s = time.perf_counter() - t0
    c = tetra.Calibration.read(str(cal))
    run_s = []
    for _ in range(a.repeat):
        p = tetra.Pipeline(c)
        t0 = time.perf_counter()
        run = p.run_log(g)
        run_s.append(time.perf_counter() - t0)
    print(f"epochs: {len(g)} ({run.epochs} run, {len(run)} accepted, {len(run.events)} events)")
    print(f"tetra replay (file in, attitude CSV and events out): {min(replay_s):.2f} s")
    print(f"tetra.read_gyro_log: {read_s:.2f} s")
    print(f"tetra.Pipeline.run (arrays in, arrays out):           {min(run_s):.2f} s")
    print(f"ratio Pipeline.run / tetra replay: {min(run_s) / min(replay_s):.2f} (target <= 1.2); "
          f"with read_gyro_log: {(read_s + min(run_s)) / min(replay_s):.2f}")


if __name__ == "__main__":
    main()
