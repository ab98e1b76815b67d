"""tetra.dds between real processes (ctest python_dds; docs/python.md, "DDS"): a `tetra fusion` service of its own
on a loopback domain, stepped from Python.

- Lockstep: a faulty orbit with a star tracker, stepped epoch by epoch, gives tetra.Pipeline's attitudes and events
  on the same epochs to the last bit (no tolerance: the same library on the same epochs, doubles carried as they
  are by CDR).
- A Subscriber reads the same run's Health and events; commands are acknowledged (and refused with a reason).
- Errors: wrong arrays raise ValueError before anything is written; no service raises TimeoutError / tetra.Error
  within the timeout given; Ctrl-C in a wait raises KeyboardInterrupt within 0.2 s.
- Real time: gyro epochs paced by the wall clock and a star tracker of its own (ReferencePublisher) delivering
  50-250 ms late: every reference fused at its own time (Health.references_delayed), none too late.
- A service restarted under a lockstep run: its attitudes refused (tetra.Error), not mixed into the run.
Domains 205-209.
"""
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import tetra
import tetra.dds as dds
from dds_helpers import start_fusion, stop_fusion

SOURCE = pathlib.Path(os.environ.get("TETRA_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
DOMAIN = 206
UNIT = "py-lock"
ORBIT = {"scenario": "orbit", "duration_s": 40, "rate_hz": 100,
         "acs": {"amplitude_deg": 0.05, "peak_accel_dps2": 1.0e-5},
         "reference": {"rate_hz": 1, "noise_arcsec": 5}, "faults": ["gyro=2,kind=bias,at=15,size=0.01"]}
PIPELINE = {"clear_after_s": 10}


def fusion_config(path, unit, pipeline, speed=0.02):
    lines = "".join(f"  {k}: {v}\n" for k, v in pipeline.items()) or "  {}\n"
    # speed 0.02: the service's silence deadline (3 / (100 Hz * 0.02) = 1.5 s of wall clock) covers a step of
    # a Python simulator on a loaded machine (a stall beyond it would make the gyros absent: not the in-process
    # epochs); max_latency_s is not needed in lockstep (each sample says how many the epoch has).
    path.write_text(f"unit: {unit}\ncalibration: {SOURCE / 'examples' / 'seed_unit.yaml'}\nsample_rate_hz: 100\n"
                    f"speed: {speed}\nhealth_period_s: 0.5\npipeline:\n{lines}")
    return path


def start_service(tmp, config, domain):
    return start_fusion(os.environ["TETRA_BIN"], config, domain, tmp / "fusion.log")


def stop(proc):
    assert stop_fusion(proc) == 0


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    os.environ["CYCLONEDDS_URI"] = "file://" + str(SOURCE / "config" / "cyclonedds-loopback.xml")
    tmp = tmp_path_factory.mktemp("fusion")
    proc = start_service(tmp, fusion_config(tmp / "fusion.yaml", UNIT, PIPELINE), DOMAIN)
    yield proc
    stop(proc)


def same_bits(a, b):
    a, b = np.ascontiguousarray(a, dtype=np.float64), np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def test_lockstep_equals_the_pipeline_in_process(service):
    run = tetra.sim(ORBIT, seed=5)
    log = run.log
    cal = tetra.Calibration.read(str(SOURCE / "examples" / "seed_unit.yaml"))
    expected = tetra.Pipeline(cal, PIPELINE).run_log(log)
    sub = dds.Subscriber(UNIT, domain=DOMAIN)
    got = []
    start = time.monotonic()
    with dds.Lockstep(UNIT, gyros=4, rate_hz=100, domain=DOMAIN) as lock:
        for k in range(len(log.time_s)):
            ref = log.reference_wxyz[k] if log.reference_present[k] else None
            got.append(lock.step(log.time_s[k], log.values[k], log.present[k], ref, timeout_s=5.0))
    wall = time.monotonic() - start
    print(f"[ figure ] lockstep: {len(got)} epochs in {wall:.1f} s ({1e3 * wall / len(got):.2f} ms an epoch)")
    assert len(got) == len(expected)
    assert same_bits(np.array([a.q_RB_wxyz for a in got]), expected.q_RB_wxyz)
    assert same_bits(np.array([a.sigma_rad for a in got]) * (180 / np.pi), expected.sigma_B_deg)
    assert same_bits(np.array([a.omega_BR_B_rad_s for a in got]) * (180 / np.pi), expected.omega_BR_B_dps)
    assert same_bits(np.array([a.protection_level_rad for a in got]) * (180 / np.pi),
                     expected.protection_level_B_deg)
    assert [a.mode for a in got] == list(expected.mode_names)
    assert [a.gyros_mask for a in got] == list(expected.gyros)
    # The stamps are the epochs' sensor times in whole ns (time_s = stamp_ns * 1e-9, not the float given).
    assert np.abs(np.array([a.stamp_ns for a in got]) - expected.time_s * 1e9).max() <= 1.0

    # The same run's events (the pipeline's, in order, the same lines) and its last Health.
    # (its mode may already say LOST: the gyros went silent when the steps ended, 1.5 s of wall clock)
    health = sub.wait_health(10.0, lambda h: h.counters["epochs_accepted"] == len(got))
    assert health.counters["samples_late"] == 0 and health.references_delayed == 0
    assert health.reference_state == "accepted" and health.references_too_late == 0
    sub.poll(1.0)
    pipeline_types = {e["type"] for e in expected.events}
    wire = [e.json for e in sub.events if e.type in pipeline_types]
    assert wire == [e["json"] for e in expected.events]
    assert {"detected", "isolated"} <= pipeline_types


def test_subscriber_dataclasses_and_units(service):
    sub = dds.Subscriber(UNIT, domain=DOMAIN)
    health = sub.wait_health(5.0)  # transient-local: the latest Health comes to a late joiner
    assert isinstance(health, dds.Health) and health.unit == UNIT
    assert health.reference_horizon_s == 0.5 and health.health_period_s == 0.5
    assert len(health.gyros) == 4 and isinstance(health.gyros[0], dds.GyroStatus)
    assert set(health.counters) >= {"epochs_accepted", "samples_late", "unit_silences"}
    with pytest.raises(TimeoutError, match="no Attitude of unit 'py-lock' within 0.2 s"):
        sub.wait_attitude(0.2)
    # One call at a time: a second thread's call while a wait runs (the GIL released) is refused (on a domain
    # of no service: nothing arrives to end the wait early).
    import threading
    quiet = dds.Subscriber("nobody", domain=DOMAIN + 1)
    waiting = threading.Thread(target=quiet.poll, args=(1.0,))
    waiting.start()
    time.sleep(0.2)
    with pytest.raises(RuntimeError, match="Subscriber.poll: another call is running on this object"):
        quiet.poll(0.0)
    waiting.join()


def test_commands_acknowledged_and_refused(service):
    assert not dds.command(UNIT, "reset", domain=DOMAIN).refused  # every gyro back (gyro 2 was isolated)
    ack = dds.command(UNIT, "exclude", 3, domain=DOMAIN, operator="tester", origin="pytest")
    assert ack.type == "command" and not ack.refused and ack.operator == "tester" and ack.origin == "pytest"
    assert dds.command(UNIT, "reinstate", 3, domain=DOMAIN).refused is False
    refused = dds.command(UNIT, "reinstate", 3, domain=DOMAIN)
    assert refused.refused and refused.detail
    with pytest.raises(tetra.BadInputError, match="reset takes no gyro id"):
        dds.command(UNIT, "reset", 2, domain=DOMAIN)
    t = time.monotonic()
    with pytest.raises(TimeoutError, match="(no fusion service found|no acknowledgement from unit nobody) within 0.3 s"):
        dds.command("nobody", "reset", domain=DOMAIN, timeout_s=0.3)
    assert time.monotonic() - t < 2.0


def test_bad_arguments_raise_before_anything_is_written(service):
    with dds.Lockstep(UNIT, domain=DOMAIN) as lock:
        with pytest.raises(ValueError, match="raw: expected 4 values"):
            lock.step(1.0, [0.0, 0.0, 0.0])
        with pytest.raises(ValueError, match="reference_wxyz: expected 4 values"):
            lock.send(1.0, [0.0] * 4, None, [1.0, 0.0])
        with pytest.raises(ValueError, match="timeout_s"):
            lock.step(1.0, [0.0] * 4, timeout_s=-1)
    with pytest.raises(tetra.BadInputError, match="unit"):
        dds.Subscriber("x" * 40, domain=DOMAIN)
    with pytest.raises(ValueError, match="domain"):
        dds.Subscriber(UNIT, domain=999)


def test_no_service_within_the_timeout():
    t = time.monotonic()
    with pytest.raises(tetra.Error, match="only 0 of 1 GyroSample readers appeared within 0.5"):
        dds.Lockstep("nobody", domain=DOMAIN + 1, timeout_s=0.5)
    with pytest.raises(TimeoutError, match="no AttitudeReference reader"):
        dds.ReferencePublisher("nobody", domain=DOMAIN + 1, timeout_s=0.3)
    assert time.monotonic() - t < 3.0


@pytest.mark.parametrize("call", ["dds.Lockstep('nobody', domain=%d, timeout_s=60)",
                                  "dds.Subscriber('nobody', domain=%d).wait_attitude(60)"])
def test_ctrl_c_in_a_wait(call):
    code = textwrap.dedent(f"""
        import sys, time, tetra.dds as dds
        print("ready", flush=True)
        try:
            {call % (DOMAIN + 2)}
        except KeyboardInterrupt:
            print("interrupted", time.monotonic(), flush=True)
    """)
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "ready"
    time.sleep(1.0)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    line = child.stdout.readline().split()
    assert child.wait(timeout=10) == 0 and line and line[0] == "interrupted", line
    print(f"[ figure ] Ctrl-C in {call.split('(')[0]}: KeyboardInterrupt {1e3 * (float(line[1]) - sent):.0f} ms "
          "after SIGINT")
    assert float(line[1]) - sent < 0.2


def test_a_tracker_of_its_own_late_is_fused_at_its_time(tmp_path):
    proc = start_service(tmp_path, fusion_config(tmp_path / "rt.yaml", "py-rt", {}, speed=1), DOMAIN + 3)
    try:
        run = tetra.sim({"scenario": "orbit", "duration_s": 4, "rate_hz": 100}, seed=7)
        log, truth = run.log, run.truth
        sub = dds.Subscriber("py-rt", domain=DOMAIN + 3)
        gyros = dds.GyroPublisher("py-rt", rate_hz=100, domain=DOMAIN + 3)
        tracker = dds.ReferencePublisher("py-rt", domain=DOMAIN + 3)
        due, sent, late_s = [], 0, []  # (wall time to send, stamp, q): 50, 150, 250 ms after the image
        start = time.monotonic()
        for k, t in enumerate(log.time_s):
            time.sleep(max(0.0, start + t - time.monotonic()))
            stamp = gyros.send(t, log.values[k])
            if k % 20 == 10:
                due.append((time.monotonic() + 0.05 + 0.1 * (k // 20 % 3), stamp, truth.q_RB_wxyz[k]))
            while due and due[0][0] <= time.monotonic():
                _, ref_stamp, q = due.pop(0)
                tracker.send(ref_stamp, q)
                late_s.append(time.monotonic() - start - ref_stamp * 1e-9)
                sent += 1
        attitudes = gyros.attitudes(timeout_s=1.0)
        gyros.close()
        health = sub.wait_health(5.0, lambda h: h.references_delayed + h.references_too_late >= sent)
    finally:
        stop(proc)
    print(f"[ figure ] real time: {len(attitudes)} attitudes of {len(log.time_s)} epochs; {sent} references "
          f"{min(late_s):.3f}-{max(late_s):.3f} s late: {health.references_delayed} fused at their time, "
          f"{health.references_too_late} too late")
    assert len(attitudes) >= 0.95 * len(log.time_s) and isinstance(attitudes[0], dds.Attitude)
    assert min(late_s) >= 0.05 and health.references_delayed == sent and health.references_too_late == 0
    assert health.reference_state == "accepted"


def test_a_restarted_service_is_refused_in_lockstep(tmp_path):
    # (A second service of a running unit refuses to start, services/fusion/duplicate_watch.hpp; a restarted
    # one is a new Attitude writer whose estimate starts afresh: a lockstep run would mix the two.)
    config = fusion_config(tmp_path / "f.yaml", "py-dup", {})
    proc = start_service(tmp_path, config, 205)
    raw = [2e-4, 4e-4, 2e-4, -3e-4]
    try:
        with dds.Lockstep("py-dup", domain=205) as lock:
            for k in range(50):
                lock.step(k / 100, raw)
            stop(proc)
            proc = start_service(tmp_path, config, 205)
            with pytest.raises(tetra.Error, match="Attitude of unit py-dup from a second writer: two fusion "
                                                  "services \\(or one restarted\\)"):
                for k in range(50, 100):
                    try:
                        lock.step(k / 100, raw, timeout_s=1.0)
                    except TimeoutError:
                        pass  # an epoch written before the new service had discovered the writer
    finally:
        stop(proc)
