"""tetra over DDS from Python, without a Cyclone DDS Python binding (Debian 12 ships none).

Three small processes carry the traffic, each speaking lines on a pipe (docs/python.md, "DDS"; tetra.dds needs no pipes):

  GyroPublisher  -> `tetra ingest` (stdin line protocol `TIME_S,all,RAW1,...,RAWN`) -> GyroSample
  StarTracker    -> examples/dds/star_tracker (stdin `STAMP_NS QW QX QY QZ`)      -> AttitudeReference
  Subscriber     <- examples/dds/attitude_subscriber (JSON lines, SI units)     <- Attitude, Health, FdiEvent

Every value is in the wire's units: rad, rad/s, ns, volts; quaternions body -> reference, scalar first.
"""
import json
import subprocess


class Subscriber:
    """Every Attitude, Health and FdiEvent of `unit` as dicts (key "type": attitude, health, event)."""

    def __init__(self, exe, unit, domain, seconds=0.0):
        self.proc = subprocess.Popen([exe, unit, "--domain", str(domain), "--seconds", str(seconds)],
                                     stdout=subprocess.PIPE, text=True, bufsize=1)

    def __iter__(self):
        for line in self.proc.stdout:
            yield json.loads(line)

    def close(self):
        if self.proc.poll() is None:
            self.proc.terminate()
        self.proc.wait(timeout=10)


class StarTracker:
    """Publishes attitude references: send(stamp_ns, q_RB_wxyz) writes one at once, stamped with its time."""

    def __init__(self, exe, unit, domain):
        self.proc = subprocess.Popen([exe, unit, "--domain", str(domain)], stdin=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, bufsize=1)
        ready = self.proc.stderr.readline()  # the service's reader matched
        if ready.strip() != "ready":
            raise RuntimeError("star_tracker: " + ready + self.proc.stderr.read())

    def send(self, stamp_ns, q_RB_wxyz):
        self.proc.stdin.write("%d %.17g %.17g %.17g %.17g\n" % (stamp_ns, *q_RB_wxyz))
        self.proc.stdin.flush()

    def close(self):
        self.proc.stdin.close()
        return self.proc.wait(timeout=10)


class GyroPublisher:
    """Publishes gyro epochs through `tetra ingest`: send(time_s, raw_V) with one raw value [V] per gyro."""

    def __init__(self, tetra, unit, domain, gyros, rate_hz):
        self.proc = subprocess.Popen(
            [tetra, "ingest", "--unit", unit, "--domain", str(domain), "--gyros", str(gyros),
             "--rate-hz", str(rate_hz), "--quiet"], stdin=subprocess.PIPE, text=True, bufsize=1)

    def send(self, time_s, raw_V):
        self.proc.stdin.write("%.9f,all,%s\n" % (time_s, ",".join("%.17g" % v for v in raw_V)))
        self.proc.stdin.flush()

    def close(self):
        self.proc.stdin.close()
        return self.proc.wait(timeout=20)
