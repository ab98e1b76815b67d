#!/usr/bin/python3
"""Attacks on `tetra ground` measured through raw sockets (figures for docs/ground.md):

guess: one guesser (one connection, kept alive, the next guess as soon as the last is answered) posts
    wrong passwords for alice for --seconds; with --operator the operator signs in with the right
    password from another loopback address (127.0.0.2) once a second. Prints the guesses the ground
    checked (401) per second, the refusals before any check (429), the busy answers (503), and the
    operator's sign-ins by status.
unread: one connection sends pipelined `GET /login.html` requests as fast as the socket takes them for
    --seconds and reads nothing (`--no-auth`). Prints the bytes the ground took and its resident memory
    before and after.

    bench/ground_attacks.py guess --tetra build/tetra --seconds 30 --operator
    bench/ground_attacks.py unread --tetra build/tetra --seconds 15
"""

import argparse
import collections
import json
import os
import re
import select
import socket
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "ground"))
from abuse_test import free_port, rss_mib  # noqa: E402


def start_ground(tetra, argv, log):
    """`tetra ground ARGV` on a free loopback port, once it accepts connections: (process, port)."""
    port = free_port()
    ground = subprocess.Popen([tetra, "ground", "--listen", f"127.0.0.1:{port}"] + argv, stdout=log,
                              stderr=subprocess.STDOUT)
    for _ in range(300):
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            break
        except OSError:
            time.sleep(0.1)
    return ground, port

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


def guess(args):
    work = tempfile.mkdtemp(prefix="tetra_guess_")
    users = os.path.join(work, "users")
    subprocess.run([args.tetra, "ground", "passwd", "alice", "--role", "commander", "--users", users,
                    "--password-stdin"], input="correct horse battery\n", text=True, check=True,
                   stdout=subprocess.DEVNULL)
    log = open(os.path.join(work, "ground.log"), "w")
    ground, port = start_ground(args.tetra, ["--users", users], log)
    guesses = collections.Counter()
    operator = collections.Counter()
    stop = threading.Event()
    try:
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


def unread(args):
    ground, port = start_ground(args.tetra, ["--no-auth"], subprocess.DEVNULL)
    try:
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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("attack", choices=["guess", "unread"])
    ap.add_argument("--tetra", required=True)
    ap.add_argument("--seconds", type=float, default=30)
    ap.add_argument("--operator", action="store_true", help="guess: the operator signs in from 127.0.0.2 meanwhile")
    ap.add_argument("--bytes", type=int, default=1 << 30, help="unread: stop after sending this much")
    args = ap.parse_args()
    return guess(args) if args.attack == "guess" else unread(args)


if __name__ == "__main__":
    sys.exit(main())
