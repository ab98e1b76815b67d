"""tetra.Pipeline against `tetra replay`: the attitude and the events, to the last bit."""
import threading
import time

import numpy as np
import pytest

import tetra
from conftest import EXAMPLES, read_csv_exact, same_bits

ATTITUDE_COLUMNS = ["time_s", "qw", "qx", "qy", "qz", "wx_dps", "wy_dps", "wz_dps", "sigma_deg",
                    "sigma_x_deg", "sigma_y_deg", "sigma_z_deg", "bias_1_dps", "bias_2_dps", "bias_3_dps",
                    "bias_4_dps", "pl_x_deg", "pl_y_deg", "pl_z_deg"]


@pytest.fixture(scope="module")
def cal():
    return tetra.Calibration.read(str(EXAMPLES / "seed_unit.yaml"))


def test_run_equals_replay(orbit_fault_files, cal):
    d = orbit_fault_files
    log = tetra.read_gyro_log(str(d / "log.csv"))
    run = tetra.Pipeline(cal).run_log(log)
    att = read_csv_exact(d / "att.csv")
    frame = run.attitude_frame()
    assert len(frame) == len(att) == run.epochs
    for c in ATTITUDE_COLUMNS:
        assert same_bits(frame[c].to_numpy(), att[c].to_numpy()), c
    assert list(frame["mode"]) == list(att["mode"])
    used = ["".join(str(i) for i in range(1, 5) if m >> (i - 1) & 1) for m in run.gyros]
    assert used == [str(g) for g in att["gyros"]]
    events = (d / "events.jsonl").read_text().splitlines()
    assert [e["json"] for e in run.events] == events
    assert any(e["type"] == "isolated" and e["gyro"] == 2 for e in run.events)
    assert run.events_frame().shape[0] == len(events)


def test_step_equals_run(orbit_fault_files, cal):
    log = tetra.read_gyro_log(str(orbit_fault_files / "log.csv"))
    n = 80
    whole = tetra.Pipeline(cal).run(log.time_s[:n], log.values[:n], log.present[:n], log.reference_wxyz[:n])
    p = tetra.Pipeline(cal)
    q = []
    for k in range(n):
        ref = log.reference_wxyz[k] if log.reference_present[k] else None
        r = p.step(log.time_s[k], log.values[k], log.present[k], ref)
        assert r["accepted"]
        q.append(r["attitude"]["q_RB_wxyz"])
    assert same_bits(np.array(q), whole.q_RB_wxyz)
    assert p.health()["counters"]["epochs_accepted"] == n


def test_config_dict_file_and_commands(tmp_path, cal):
    (tmp_path / "c.yaml").write_text("pipeline:\n  clear_after_s: 12\n")
    a = tetra.pipeline_config({"clear_after_s": 12})
    b = tetra.pipeline_config(str(tmp_path / "c.yaml"))
    assert a.describe() == b.describe()
    p = tetra.Pipeline(cal, {"latitude_deg": 45.0})
    assert p.config.latitude_deg == 45.0
    assert "gyro 1:" in p.describe_thresholds()
    ack = p.exclude(3, 0)
    assert ack["type"] == "command" and ack["outcome"] == "done"
    assert p.health()["gyros"][2]["state"] == "excluded"
    p.reset()
    assert p.health()["gyros"][2]["state"] == "ok"


def test_pipeline_errors(cal, tmp_path):
    with pytest.raises(tetra.BadInputError, match="bogus"):
        tetra.Pipeline(cal, {"bogus": 1})
    with pytest.raises(tetra.BadInputError, match="latitude_deg"):
        tetra.Pipeline(cal, {"latitude_deg": 100.0})
    p = tetra.Pipeline(cal)
    t = np.arange(10) * 0.1
    with pytest.raises(ValueError, match=r"raw: expected a 2-D array of shape \(n, 4\)"):
        p.run(t, np.zeros((10, 3)))
    with pytest.raises(ValueError, match="one row per time_s"):
        p.run(t, np.zeros((9, 4)))
    bad_t = t.copy()
    bad_t[3] = np.nan
    with pytest.raises(ValueError, match=r"time_s\[3\]: NaN"):
        p.run(bad_t, np.zeros((10, 4)))
    with pytest.raises(ValueError, match="present"):
        p.run(t, np.zeros((10, 4)), present=np.ones((10, 3)))
    with pytest.raises(TypeError, match="raw"):
        p.run(t, np.full((10, 4), "x"))
    with pytest.raises(ValueError, match="reference_present"):
        p.run(t, np.zeros((10, 4)), reference_present=np.ones(10))


def test_nan_samples_and_other_dtypes(cal):
    p = tetra.Pipeline(cal)
    t = np.arange(50) * 0.1
    raw = np.tile(cal.bias_V, (50, 1))
    raw[10, 1] = np.nan  # an invalid sample: counted, not an error
    run = p.run(t, raw.astype(np.float32))  # converted once
    assert run.epochs == 50
    assert p.health()["counters"]["samples_invalid"] == 1


def test_run_releases_the_gil(cal):
    """Another Python thread runs while Pipeline.run works. With the GIL held it could run only in the
    switch intervals (5 ms) at the run's start and end: its ticks are counted in the middle of the run only,
    more than 20 ms from either end (the run of 200 000 epochs lasts a few hundred ms)."""
    t = np.arange(200000) * 0.01
    raw = np.tile(cal.bias_V, (len(t), 1))
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())

    p = tetra.Pipeline(cal)
    th = threading.Thread(target=count)
    th.start()
    try:
        t0 = time.perf_counter()
        p.run(t, raw)
        t1 = time.perf_counter()
    finally:
        stop.set()
        th.join()
    assert t1 - t0 > 0.05, "the run is too short to tell"
    assert any(t0 + 0.02 < x < t1 - 0.02 for x in ticks)
