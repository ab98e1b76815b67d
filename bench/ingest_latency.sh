#!/usr/bin/env bash
# `tetra ingest` from a pseudo-terminal: 100 Hz x 4 gyros (one line per gyro sample, 400 lines/s) for
# SECONDS (default 60) into `tetra record` on a private loopback domain. Checks that no line is lost (every
# epoch recorded, nothing malformed) and prints ingest's read -> written latency (p50, p99, max).
# Target: 0 lines lost, p99 <= 1 ms.
#
# usage: bench/ingest_latency.sh [BUILD_DIR=build] [SECONDS=60] [DOMAIN=61]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
seconds=${2:-60}
domain=${3:-61}
work=$(mktemp -d /tmp/tetra-ingest-bench-XXXXXX)
trap 'rm -rf "$work"' EXIT
export CYCLONEDDS_URI="file://$PWD/config/cyclonedds-loopback.xml"
echo "load: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"

python3 - "$build/tetra" "$work" "$seconds" "$domain" <<'EOF'
import os, pty, subprocess, sys, time, tty, fcntl, termios, struct
tetra, work, seconds, domain = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
master, slave = pty.openpty()
tty.setraw(slave)
device = os.ttyname(slave)
record = subprocess.Popen([tetra, "record", "--unit", "bench", "--gyros", "4", "--rate", "100", "--domain",
                           domain, "-o", work + "/rec.csv", "--until-idle"],
                          stdout=open(work + "/record.log", "w"), stderr=subprocess.STDOUT)
ingest = subprocess.Popen([tetra, "ingest", "--serial", device, "--baud", "115200", "--unit", "bench", "--gyros",
                           "4", "--rate-hz", "100", "--domain", domain, "--quiet"],
                          stdout=open(work + "/ingest.log", "w"), stderr=subprocess.STDOUT)
epochs = int(seconds * 100)
start = time.monotonic()
for k in range(epochs):
    due = start + k / 100.0
    now = time.monotonic()
    if due > now:
        time.sleep(due - now)
    t = "%.2f" % (k / 100.0)
    os.write(master, "".join("%s,%d,0.%d%06d\n" % (t, g, g, k) for g in range(1, 5)).encode())
while struct.unpack("i", fcntl.ioctl(slave, termios.FIONREAD, b"\0\0\0\0"))[0] > 0:
    time.sleep(0.01)
time.sleep(0.3)
os.close(master)
os.close(slave)
ingest.wait(timeout=30)
record.wait(timeout=30)
print(open(work + "/ingest.log").read(), end="")
rows = sum(1 for line in open(work + "/rec.csv") if line and not line.startswith("#")) - 1
print("lines written: %d (%d epochs x 4 gyros); epochs recorded: %d; lost: %d" % (epochs * 4, epochs, rows, epochs - rows))
sys.exit(0 if rows == epochs else 1)
EOF
