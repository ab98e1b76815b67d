#!/usr/bin/python3
"""A client that sends and never reads, against `tetra ground --no-auth`: one connection sends pipelined
`GET /login.html` requests as fast as the socket takes them for --seconds (or up to --bytes) and reads
nothing. Prints the bytes the ground took and its resident memory before and after (docs/ground.md,
"Limits"). The ground's own reading is bounded: the kernel's buffers are all the sender fills.

    bench/ground_unread.py --tetra build/tetra --seconds 20
"""

import argparse
import os
import select
import socket
import subprocess
import sys
import time


def rss_mib(pid):
    with open(f"/proc/{pid}/status", encoding="ascii") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tetra", required=True)
    ap.add_argument("--seconds", type=float, default=20)
    ap.add_argument("--bytes", type=int, default=1 << 30)
    args = ap.parse_args()
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    ground = subprocess.Popen([args.tetra, "ground", "--no-auth", "--listen", f"127.0.0.1:{port}"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for _ in range(300):
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                time.sleep(0.1)
        before = rss_mib(ground.pid)
        request = f"GET /login.html HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode()
        batch = request * (65536 // len(request))
        sock = socket.create_connection(("127.0.0.1", port))
        sock.setblocking(False)
        sent = 0
        start = time.monotonic()
        while time.monotonic() - start < args.seconds and sent < args.bytes:
            _, writable, _ = select.select([], [sock], [], 1.0)
            if not writable:
                continue
            try:
                sent += sock.send(batch)
            except BlockingIOError:
                pass
            except OSError:
                break
        after = rss_mib(ground.pid)
        print(f"{time.monotonic() - start:.0f} s sending, never reading: the ground took {sent / 2**20:.1f} MiB; "
              f"resident {before:.1f} MiB before, {after:.1f} MiB after")
        sock.close()
    finally:
        ground.terminate()
        ground.wait()
    return 0


if __name__ == "__main__":
    sys.exit(main())
