#!/usr/bin/python3
"""Latency from a Health write to its display in the browser: `tetra fusion` + `tetra sim --dds` +
`tetra ground` and headless Chromium on the unit's status view (as tests/ground/browser_test.py).
For each Health the page records Date.now() minus the Health's DDS source timestamp right after
updating the view (same host, same clock: the write in the service -> DDS -> the bridge -> the event
stream -> the page's JavaScript and DOM update; the paint is not included).

    bench/ground_latency.py [--seconds 60]

Run it in a private network namespace:
    unshare -n bash -c 'ip link set lo up; bench/ground_latency.py'
"""

import argparse
import os
import signal
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "ground"))
from browser_test import UNIT, free_port, http_ready, start_browser  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--domain", default="187")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    args = ap.parse_args()
    os.environ["CYCLONEDDS_URI"] = "file://" + os.path.join(ROOT, "config", "cyclonedds-loopback.xml")
    tetra = os.path.join(args.build, "tetra")
    data = os.path.join(ROOT, "tests", "ground", "data")
    port = free_port()
    domain = ["--domain", args.domain]
    null = subprocess.DEVNULL
    children = [
        subprocess.Popen([tetra, "ground", "--listen", f"127.0.0.1:{port}", "--no-auth"] + domain, stdout=null,
                         stderr=null),
        subprocess.Popen([tetra, "fusion", "--config", os.path.join(data, "fusion.yaml")] + domain,
                         stdout=null, stderr=null),
        subprocess.Popen([tetra, "sim", "orbit", "--dds", "--dds-unit", UNIT, "--unit",
                          os.path.join(data, "calibration.yaml"), "--rate-hz", "50", "--minutes",
                          str(args.seconds / 60 + 1), "--reference-hz", "0", "--speed", "1",
                          "--wait-readers", "1"] + domain, stdout=null, stderr=null),
    ]
    driver = start_browser()
    try:
        assert http_ready(port, 30)
        driver.get(f"http://127.0.0.1:{port}/#/browse/tetra:units/tetra:unit~{UNIT}")
        time.sleep(args.seconds)
        lat = sorted(driver.execute_script("return window.tetraHealthLatencyMs || []"))
    finally:
        driver.quit()
        for c in children:
            c.send_signal(signal.SIGTERM)
            c.wait()
    with open("/proc/loadavg") as f:
        load = " ".join(f.read().split()[:3])
    if not lat:
        print("ground_latency: no Health displayed")
        return 1
    q = lambda p: lat[min(len(lat) - 1, int(p * len(lat)))]  # noqa: E731
    print(f"ground_latency: {len(lat)} Health displays over {args.seconds:.0f} s; Health write -> display [ms]: "
          f"p50 {q(0.5):.1f}, p90 {q(0.9):.1f}, p99 {q(0.99):.1f}, max {lat[-1]:.1f}; load average {load}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
