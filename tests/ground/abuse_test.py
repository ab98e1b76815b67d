#!/usr/bin/python3
"""The ground station under abuse, through raw sockets: `tetra ground --no-auth --max-streams 1000`
holds 1,000 open event streams and refuses the next with 503; 100 slow clients send their requests a
byte a second; meanwhile the API answers every request (a socket timeout of 5 s only turns a hang into
a failure); the slow clients are closed at the request deadline; 4,200 idle connections from one
address leave an operator on another answered. Prints the API's latency and the
ground's resident memory (figures for docs/ground.md; `--requests 1000` for the bench figure); with
`--commands N`, also N commands' round trips (POST /api/command to its acknowledgement through a
`tetra fusion` of tests/ground/data/fusion.yaml, the 1,000 streams held). Latency is reported, never a
pass/fail condition.
"""

import argparse
import json
import os
import re
import resource
import socket
import subprocess
import sys
import threading
import time

STREAMS = 1000
SLOW = 100
IDLE = 4200


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def rss_mib(pid):
    with open(f"/proc/{pid}/status", encoding="ascii") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def connect(port, timeout=5.0):
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return s


def status_of(sock):
    head = b""
    while b"\r\n" not in head:
        chunk = sock.recv(4096)
        if not chunk:
            break
        head += chunk
    m = re.match(rb"HTTP/1\.1 (\d+)", head)
    return int(m.group(1)) if m else -1


def get(port, path):
    """One GET on a new connection: (status, seconds)."""
    start = time.perf_counter()
    with connect(port) as s:
        s.sendall(f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n".encode())
        data = b""
        while True:
            chunk = s.recv(65536)
            if not chunk:
                break
            data += chunk
    m = re.match(rb"HTTP/1\.1 (\d+)", data)
    return (int(m.group(1)) if m else -1), time.perf_counter() - start


def post_command(port, csrf, unit):
    """One FDI reset on a new connection, to its acknowledgement: (status, seconds)."""
    body = json.dumps({"unit": unit, "action": "reset"}).encode()
    head = (f"POST /api/command HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n"
            f"Content-Type: application/json\r\nX-CSRF-Token: {csrf}\r\nContent-Length: {len(body)}\r\n\r\n")
    start = time.perf_counter()
    with connect(port, 10) as s:
        s.sendall(head.encode() + body)
        data = b""
        while True:
            chunk = s.recv(65536)
            if not chunk:
                break
            data += chunk
    m = re.match(rb"HTTP/1\.1 (\d+)", data)
    return (int(m.group(1)) if m else -1), time.perf_counter() - start


def command_round_trips(port, count):
    """`count` resets, one at a time, once the service's unit is heard: their round trips [ms]."""
    csrf = None
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:  # the service's first Health: its unit is known to the ground
        with connect(port) as s:
            s.sendall(f"GET /api/session HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n".encode())
            csrf = json.loads(s.makefile("rb").read().split(b"\r\n\r\n", 1)[1])["csrf"]
        code, _ = get(port, "/api/history?unit=ground%20test&kind=health&max=1")
        if code == 200:
            break
        time.sleep(0.5)
    times = []
    for _ in range(count):
        code, seconds = post_command(port, csrf, "ground test")
        if code != 200:
            raise RuntimeError(f"a command: status {code}")
        times.append(seconds * 1000.0)
        time.sleep(0.2)
    return times


def percentile(values, q):
    v = sorted(values)
    return v[min(len(v) - 1, int(q * len(v)))]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tetra", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--requests", type=int, default=100, help="API requests timed under load")
    ap.add_argument("--domain", default="184")  # private to this test (tests/CMakeLists.txt)
    ap.add_argument("--publisher", help="bench/ground_load_publisher: 10 units at 100 Hz stream while measured")
    ap.add_argument("--spread", type=float, default=0.0, help="[s] spread the timed requests over this long")
    ap.add_argument("--commands", type=int, default=0,
                    help="commands timed to their acknowledgement (a tetra fusion started for them)")
    args = ap.parse_args()
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))
    os.environ["CYCLONEDDS_URI"] = "file://" + os.path.join(args.source, "config", "cyclonedds-loopback.xml")
    port = free_port()
    log_path = f"/tmp/tetra_abuse_{os.getpid()}.log"
    log = open(log_path, "w")
    ground = subprocess.Popen([args.tetra, "ground", "--listen", f"127.0.0.1:{port}", "--no-auth",
                               "--max-streams", str(STREAMS), "--domain", args.domain],
                              stdout=log, stderr=subprocess.STDOUT)
    held = []
    slow = []
    idle = []
    publisher = None
    if args.publisher:
        publisher = subprocess.Popen([args.publisher, "--domain", args.domain, "--units", "10", "--rate", "100",
                                      "--seconds", str(int(args.spread) + 120)],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    fusion = None
    if args.commands:
        fusion = subprocess.Popen([args.tetra, "fusion", "--config",
                                   os.path.join(args.source, "tests", "ground", "data", "fusion.yaml"),
                                   "--domain", args.domain], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    stop = threading.Event()
    failures = []
    commands = []
    try:
        for _ in range(300):
            try:
                connect(port, 1).close()
                break
            except OSError:
                time.sleep(0.1)
        rss_idle = rss_mib(ground.pid)

        # 1,000 event streams, each read up to its status line only (then never read again).
        for i in range(STREAMS):
            s = connect(port)
            s.sendall(f"GET /api/stream HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
            code = status_of(s)
            if code != 200:
                failures.append(f"stream {i + 1}: status {code}")
                break
            held.append(s)
        beyond, _ = get(port, "/api/stream")
        if beyond != 503:
            failures.append(f"stream {STREAMS + 1}: status {beyond}, expected 503")

        # 100 slow clients: a request a byte a second.
        request = f"GET /api/units HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode()
        for _ in range(SLOW):
            slow.append([connect(port, 30), 0])

        def trickle():
            while not stop.is_set():
                for entry in slow:
                    if entry[1] < len(request) - 1:
                        try:
                            entry[0].send(request[entry[1]:entry[1] + 1])
                            entry[1] += 1
                        except OSError:
                            entry[1] = len(request)
                stop.wait(1.0)

        threading.Thread(target=trickle, daemon=True).start()
        started_slow = time.monotonic()

        # The API under that load.
        latencies = []
        for i in range(args.requests):
            path = "/api/units" if i % 2 == 0 else "/api/history?unit=none&kind=event&max=10"
            code, seconds = get(port, path)
            if code not in (200, 404):
                failures.append(f"{path}: status {code}")
                break
            latencies.append(seconds * 1000.0)
            if args.spread:
                time.sleep(args.spread / args.requests)
        if args.commands:
            try:
                commands = command_round_trips(port, args.commands)
            except (OSError, RuntimeError, ValueError, KeyError) as e:
                failures.append(f"commands: {e!r}")
        rss_held = rss_mib(ground.pid)
        closed_slow_readers = open(log_path, encoding="utf-8", errors="replace").read().count("a slow reader")

        # The slow clients are closed at the request deadline (10 s), never served.
        stop_wait = started_slow + 25
        closed = 0
        for entry in slow:
            entry[0].settimeout(max(0.1, stop_wait - time.monotonic()))
            try:
                data = entry[0].recv(4096)
                closed += 1 if data == b"" or data.startswith(b"HTTP/1.1 408") else 0
            except ConnectionResetError:
                # A byte of the trickle that reaches the server after it closed the socket is answered by
                # a reset (RFC 793 3.4), which can overtake the 408 and the FIN: closed all the same.
                closed += 1
            except OSError:
                pass
        stop.set()
        if closed != SLOW:
            failures.append(f"{SLOW - closed} of {SLOW} slow clients not closed at the request deadline")
        log.flush()
        # 4,200 idle connections from one address (127.0.0.3): beyond its share (2048) closed at once, so
        # an operator on another address (127.0.0.4) is still answered.
        for _ in range(IDLE):
            s = socket.socket()
            s.bind(("127.0.0.3", 0))
            s.settimeout(5)
            try:
                s.connect(("127.0.0.1", port))
            except OSError:
                s.close()
                continue
            idle.append(s)
        time.sleep(0.5)
        with socket.socket() as s:
            s.bind(("127.0.0.4", 0))
            s.settimeout(5)
            try:
                s.connect(("127.0.0.1", port))
                s.sendall(f"GET /api/units HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n".encode())
                answer = s.recv(4096)
            except OSError as e:
                answer = repr(e).encode()
        if not answer.startswith(b"HTTP/1.1 200"):
            failures.append(f"an operator beside {IDLE} idle connections of another address: {answer[:40]!r}")
        refused_logged = "refused (503)" in open(log_path, encoding="utf-8", errors="replace").read()
        if not refused_logged:
            failures.append("the refused stream is not in the ground's log")

        if latencies:
            p50, p95, p99 = (percentile(latencies, q) for q in (0.5, 0.95, 0.99))
            worst = max(latencies)
            rtt = (f"; {len(commands)} commands' round trips: p50 {percentile(commands, 0.5):.1f} ms, p95 "
                   f"{percentile(commands, 0.95):.1f} ms, max {max(commands):.1f} ms" if commands else "")
            print(f"ground_abuse: {len(held)} streams held, stream {STREAMS + 1} refused ({beyond}); {SLOW} slow "
                  f"clients; {len(latencies)} API requests: p50 {p50:.1f} ms, p95 {p95:.1f} ms, p99 {p99:.1f} ms, "
                  f"max {worst:.1f} ms ({'within' if worst < 100 else 'NOT within'} 100 ms){rtt}; "
                  f"resident {rss_idle:.1f} MiB idle, "
                  f"{rss_held:.1f} MiB with the streams; {closed_slow_readers} unread streams closed at their buffer "
                  f"bound; {IDLE} idle connections of one address beside an operator answered; "
                  f"load average {os.getloadavg()[0]:.1f}")
        if failures:
            print("ground_abuse: FAILED: " + "; ".join(failures), file=sys.stderr)
            print(open(log_path, encoding="utf-8", errors="replace").read()[-2000:], file=sys.stderr)
            return 1
        return 0
    finally:
        stop.set()
        for s in held:
            s.close()
        for entry in slow:
            entry[0].close()
        for s in idle:
            s.close()
        for child in (publisher, fusion):
            if child is not None:
                child.terminate()
                child.wait()
        ground.terminate()
        try:
            ground.wait(timeout=20)
        except subprocess.TimeoutExpired:
            ground.kill()
        log.close()
        os.unlink(log_path)


if __name__ == "__main__":
    sys.exit(main())
