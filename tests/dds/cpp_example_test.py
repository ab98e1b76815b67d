#!/usr/bin/env python3
"""examples/dds/cpp_subscriber.cpp between real processes (ctest dds_cpp_example; docs/dds.md "Your own programs
on the wire"): `tetra fusion` fed by `tetra sim --dds` for 3 s at 100 Hz, read at once by the C++ subscriber and the
C one. Checks: the C++ program prints an attitude for (nearly) every epoch, each the same JSON object as the C
subscriber's for that epoch (the same wire values: no tolerance), unit quaternions; with no service it exits 1 after
its --seconds. Domain 218. Exit 0 on pass.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

from dds_helpers import start_fusion, stop_fusion, verdict


def attitudes(text):
    return [m for m in map(json.loads, text.splitlines()) if m["type"] == "attitude"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tetra", required=True)
    ap.add_argument("--examples", required=True, help="the folder examples/dds/build.sh built")
    ap.add_argument("--source", required=True)
    ap.add_argument("--domain", type=int, default=218)
    args = ap.parse_args()
    os.environ["CYCLONEDDS_URI"] = "file://" + os.path.join(args.source, "config", "cyclonedds-loopback.xml")
    d = str(args.domain)
    with tempfile.TemporaryDirectory() as work:
        fusion = start_fusion(args.tetra, os.path.join(args.source, "examples", "fusion_service.yaml"), d,
                              os.path.join(work, "fusion.log"))
        try:
            # Into files, not pipes: a full pipe would block a subscriber, and its reader would drop epochs.
            outs = [os.path.join(work, exe + ".jsonl") for exe in ("cpp_subscriber", "attitude_subscriber")]
            readers = [subprocess.Popen([os.path.join(args.examples, exe), "tetra-1", "--domain", d, "--seconds",
                                         "12"], stdout=open(out, "w"))
                       for exe, out in zip(("cpp_subscriber", "attitude_subscriber"), outs)]
            time.sleep(1.0)  # the readers discovered (the service's Attitude writer is volatile)
            subprocess.run([args.tetra, "sim", "orbit", "--dds", "--dds-unit", "tetra-1", "--domain", d, "--rate-hz",
                            "100", "--minutes", "0.05", "--seed", "4"], check=True, stdout=subprocess.DEVNULL)
            cpp_rc = readers[0].wait(timeout=30)
            readers[1].wait(timeout=30)
            cpp_out, c_out = [open(out).read() for out in outs]
        finally:
            stop_fusion(fusion)
    cpp, c = attitudes(cpp_out), attitudes(c_out)
    norms = [math.sqrt(sum(x * x for x in a["q_RB"])) for a in cpp]
    lonely = subprocess.run([os.path.join(args.examples, "cpp_subscriber"), "nobody", "--domain", d, "--seconds",
                             "0.5"], capture_output=True, text=True)
    print("[ figure ] C++ subscriber: %d attitudes (C subscriber: %d) of 300 epochs, exit %d; alone: exit %d"
          % (len(cpp), len(c), cpp_rc, lonely.returncode))
    return verdict([
        (cpp_rc == 0 and len(cpp) >= 285, "an attitude for (nearly) every epoch"),
        (cpp == c, "the same attitudes as the C subscriber, value for value"),
        (all(abs(n - 1.0) < 1e-12 for n in norms), "unit quaternions"),
        (lonely.returncode == 1 and lonely.stdout == "", "no service: nothing printed, exit 1"),
    ])


if __name__ == "__main__":
    sys.exit(main())
