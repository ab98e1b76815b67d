#!/usr/bin/python3
"""Password guessing against `tetra ground`, through raw sockets: one guesser (one connection, kept
alive, the next guess as soon as the last is answered) posts wrong passwords for alice for --seconds;
meanwhile, with --operator, the operator signs in with the right password from another loopback address
once a second. Prints the guesses the ground checked (401) per second, the refusals before any check
(429) and the busy answers (503), and the operator's sign-ins by status. Figures for docs/ground.md.

    bench/ground_guess.py --tetra build/tetra --seconds 60 --operator
"""

import argparse
import collections
import json
import os
import re
import socket
import subprocess
import sys
import tempfile
import threading
import time


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def read_reply(sock):
    """One HTTP reply on a kept-alive socket: its status (or -1 when the server closed)."""
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = sock.recv(65536)
        if not chunk:
            return -1
        data += chunk
    head, _, body = data.partition(b"\r\n\r\n")
    m = re.search(rb"Content-Length: (\d+)", head)
    length = int(m.group(1)) if m else 0
    while len(body) < length:
        chunk = sock.recv(65536)
        if not chunk:
            break
        body += chunk
    return int(head[9:12])


def login(sock, port, password, close=False):
    body = json.dumps({"user": "alice", "password": password}).encode()
    req = (f"POST /api/login HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\n"
           f"Content-Length: {len(body)}\r\n" + ("Connection: close\r\n" if close else "") + "\r\n").encode()
    sock.sendall(req + body)
    return read_reply(sock)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tetra", required=True)
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--operator", action="store_true", help="the operator signs in from 127.0.0.2 meanwhile")
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="tetra_guess_")
    users = os.path.join(work, "users")
    subprocess.run([args.tetra, "ground", "passwd", "alice", "--role", "commander", "--users", users,
                    "--password-stdin"], input="correct horse battery\n", text=True, check=True,
                   stdout=subprocess.DEVNULL)
    port = free_port()
    log = open(os.path.join(work, "ground.log"), "w")
    ground = subprocess.Popen([args.tetra, "ground", "--users", users, "--listen", f"127.0.0.1:{port}"],
                              stdout=log, stderr=subprocess.STDOUT)
    guesses = collections.Counter()
    operator = collections.Counter()
    stop = threading.Event()
    try:
        for _ in range(300):
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                time.sleep(0.1)

        def sign_ins():
            while not stop.wait(1.0):
                with socket.socket() as s:
                    s.bind(("127.0.0.2", 0))
                    s.settimeout(30)
                    s.connect(("127.0.0.1", port))
                    operator[login(s, port, "correct horse battery", close=True)] += 1

        if args.operator:
            threading.Thread(target=sign_ins, daemon=True).start()
        sock = socket.create_connection(("127.0.0.1", port), timeout=30)
        start = time.perf_counter()
        n = 0
        while time.perf_counter() - start < args.seconds:
            status = login(sock, port, f"guess{n}")
            n += 1
            guesses[status] += 1
            if status == -1:
                sock = socket.create_connection(("127.0.0.1", port), timeout=30)
        elapsed = time.perf_counter() - start
        stop.set()
    finally:
        ground.terminate()
        ground.wait()
    print(f"{args.seconds:.0f} s of guessing on one connection: {n} attempts, "
          f"{guesses[401]} passwords checked ({guesses[401] / elapsed:.2f}/s, {guesses[401] * 3600 / elapsed:.0f}/h), "
          f"{guesses[429]} refused before a check (429), {guesses[503]} busy (503), others {dict(guesses)}")
    if args.operator:
        print(f"the operator from another address, once a second: {dict(operator)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
