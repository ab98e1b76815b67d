"""Shared by the DDS tests between real processes in tests/dds/: a `tetra fusion` started and stopped, and the
verdict of a list of checks."""
import signal
import subprocess
import time


def start_fusion(tetra, config, domain, log_path, timeout_s=20.0):
    """`tetra fusion --config CONFIG --domain DOMAIN`, its output into LOG_PATH, once it says it is running."""
    proc = subprocess.Popen([tetra, "fusion", "--config", str(config), "--domain", str(domain)],
                            stdout=open(log_path, "w"), stderr=subprocess.STDOUT)
    give_up = time.monotonic() + timeout_s
    while "running" not in open(log_path).read():
        if proc.poll() is not None or time.monotonic() > give_up:
            proc.kill()
            raise RuntimeError("fusion did not start: " + open(log_path).read())
        time.sleep(0.05)
    return proc


def stop_fusion(proc):
    """SIGTERM, as an operator stops it; its exit status (0: stopped cleanly)."""
    proc.send_signal(signal.SIGTERM)
    return proc.wait(timeout=20)


def verdict(checks):
    """Prints `FAIL: what` for each (ok, what) not ok; the exit status (0: all passed)."""
    failures = [what for ok, what in checks if not ok]
    for what in failures:
        print("FAIL: " + what)
    return 1 if failures else 0
