#!/usr/bin/python3
"""The ground station under load: `tetra ground` with U units publishing Attitude at R Hz (and Health
every 0.5 s, an event every 10 s; bench/ground_load_publisher) and B browsers' event streams
connected, for S seconds. Checks that no message is lost (each stream's ids are consecutive, no
`reset`; each unit's attitude arrives at the decimated 10 Hz without a gap in sensor time) and that
memory does not grow (the ground's resident set every 10 s: it must level off once the history rings
and the stream's ring are full: the growth over the second half of the run is reported).

    bench/ground_load.py [--units 10] [--rate 100] [--browsers 5] [--seconds 600] [--history 60]

Run it in a private network namespace (loopback only):
    unshare -n bash -c 'ip link set lo up; bench/ground_load.py --seconds 120'
"""

import argparse
import http.client
import json
import os
import socket
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def rss_kib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


class StreamClient(threading.Thread):
    """One browser's event stream: counts messages, checks ids and attitude times."""

    def __init__(self, port, stop):
        super().__init__(daemon=True)
        self.port, self.stop = port, stop
        self.messages = 0
        self.id_gaps = 0
        self.resets = 0
        self.attitudes = {}
        self.attitude_gaps = 0
        self.last_id = None
        self.last_sensor = {}

    def run(self):
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        conn.request("GET", "/api/stream")
        resp = conn.getresponse()
        event, ident = None, None
        while not self.stop.is_set():
            line = resp.readline()
            if not line:
                break
            line = line.decode().rstrip("\n")
            if line.startswith("id: "):
                ident = int(line[4:])
            elif line.startswith("event: "):
                event = line[7:]
            elif line.startswith("data: "):
                self.handle(event, ident, line[6:])
            elif line == "":
                event, ident = None, None

    def handle(self, event, ident, data):
        if event == "reset":
            self.resets += 1
        if ident is None:
            return  # the snapshot sent on connection
        self.messages += 1
        if self.last_id is not None and ident != self.last_id + 1:
            self.id_gaps += 1
        self.last_id = ident
        if event == "attitude":
            m = json.loads(data)
            unit, t = m["unit"], m["sensor_time_s"]
            self.attitudes[unit] = self.attitudes.get(unit, 0) + 1
            last = self.last_sensor.get(unit)
            if last is not None and abs(t - last - 0.1) > 1e-6:
                self.attitude_gaps += 1
            self.last_sensor[unit] = t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--units", type=int, default=10)
    ap.add_argument("--rate", type=float, default=100)
    ap.add_argument("--browsers", type=int, default=5)
    ap.add_argument("--seconds", type=float, default=600)
    ap.add_argument("--history", type=float, default=60, help="[s] the ground's --history")
    ap.add_argument("--domain", default="185")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    args = ap.parse_args()
    os.environ["CYCLONEDDS_URI"] = "file://" + os.path.join(ROOT, "config", "cyclonedds-loopback.xml")
    port = free_port()
    ground = subprocess.Popen([os.path.join(args.build, "tetra"), "ground", "--listen", f"127.0.0.1:{port}",
                               "--no-auth", "--domain", args.domain, "--history", str(args.history)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(1.0)
    stop = threading.Event()
    clients = [StreamClient(port, stop) for _ in range(args.browsers)]
    for c in clients:
        c.start()
    time.sleep(0.5)
    publisher = subprocess.Popen([os.path.join(args.build, "ground_load_publisher"), "--domain", args.domain,
                                  "--units", str(args.units), "--rate", str(args.rate), "--seconds",
                                  str(args.seconds)], stdout=subprocess.PIPE, text=True)
    samples = []
    t0 = time.monotonic()
    while publisher.poll() is None:
        samples.append((time.monotonic() - t0, rss_kib(ground.pid)))
        time.sleep(10)
    published = publisher.stdout.read().strip()
    time.sleep(2)  # the last messages reach the streams
    stop.set()
    ground.terminate()
    ground.wait()
    with open("/proc/loadavg") as f:
        load = f.read().split()[:3]
    print(published)
    print(f"ground_load: {args.units} units at {args.rate:.0f} Hz, {args.browsers} streams, {args.seconds:.0f} s, "
          f"history {args.history:.0f} s; load average {' '.join(load)}")
    expected = args.seconds * 10  # attitude per unit at the decimated 10 Hz
    ok = True
    for i, c in enumerate(clients):
        per_unit = sorted(c.attitudes.values()) or [0]
        print(f"  stream {i + 1}: {c.messages} messages, id gaps {c.id_gaps}, resets {c.resets}, attitude per unit "
              f"{per_unit[0]}..{per_unit[-1]} (expected {expected:.0f}), attitude time gaps {c.attitude_gaps}")
        ok = ok and c.id_gaps == 0 and c.resets == 0 and c.attitude_gaps == 0 and len(c.attitudes) == args.units
    print("  ground resident set [MiB] every 10 s: " + " ".join(f"{kib / 1024:.1f}" for _, kib in samples))
    # Growth over the second half: by then the history rings (--history) and the stream ring (16384
    # messages, about 2 min at 10 units) are full.
    half = [kib for t, kib in samples if t >= args.seconds / 2]
    if len(half) >= 2:
        print(f"  growth over the second half of the run: {(half[-1] - half[0]) / 1024:+.1f} MiB")
    print("ground_load: " + ("no loss" if ok else "LOSS"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
