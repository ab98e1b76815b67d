"""The bindings the other files do not reach: Allan reports and noise update, operator commands, a rejected
epoch, scenario and campaign attributes, the score's per-epoch arrays."""
import json

import numpy as np
import pytest

import tetra
from conftest import EXAMPLES


def test_allan_reports_and_noise_update(tmp_path, run_cli):
    run_cli("sim", "static", "--minutes", 5, "--seed", 5, "--out", tmp_path / "log.csv")
    cal = tetra.Calibration.read(str(EXAMPLES / "seed_unit.yaml"))
    a = tetra.allan_log(str(tmp_path / "log.csv"), calibration=cal, gyros=[2], taus="octave")
    assert [g.id for g in a.gyros] == [2] and a.epochs == 3000 and a.missing_epochs == 0
    assert json.loads(a.to_json())["gyros"][0]["id"] == 2
    assert "N" in a.table()
    only_2 = a.update_calibration(cal)  # gyro 2's noise terms; the others' sections as they were
    assert only_2.noise[1]["arw_dps_rtHz"] == a.gyros[0].result.fit.reported["N"]
    assert only_2.noise[0] == cal.noise[0]
    whole = tetra.allan_log(str(tmp_path / "log.csv"), calibration=cal)
    updated = whole.update_calibration(cal)
    assert updated.noise[0]["arw_dps_rtHz"] == whole.gyros[0].result.fit.reported["N"]
    r = whole.gyros[0].result
    assert r.noise_type and len(r.edf) == len(r.tau_s) and r.fit.points_used > 0
    assert set(r.fit.observed) == {"Q", "N", "B", "K", "R"}


def test_commands_health_and_rejected_epochs():
    cal = tetra.Calibration.seed_unit()
    p = tetra.Pipeline(cal)
    raw = cal.bias_V
    assert p.step(1.0, raw)["accepted"]
    r = p.step(1.0, raw)  # time not increasing: rejected and counted
    assert not r["accepted"] and r["attitude"] is None
    assert p.health()["counters"]["epochs_rejected_time"] == 1
    assert p.exclude(1, 1_000_000_000)["outcome"] == "done"
    assert p.reinstate(1, 1_000_000_000)["outcome"] == "done"
    assert p.reset_command(1_000_000_000)["type"] == "command"
    h = p.health()
    assert h["mode"] in tetra.MODE_NAMES and len(h["gyros"]) == 4
    with pytest.raises(ValueError, match="raw"):
        p.step(2.0, raw[:3])


def test_units_dps_and_absent_samples():
    cal = tetra.Calibration.seed_unit()
    p = tetra.Pipeline(cal, units_dps=True)
    assert p.config.raw_units_dps
    t = np.arange(20) * 0.1
    present = np.ones((20, 4), dtype=bool)
    present[5, 3] = False
    run = p.run(t, np.zeros((20, 4)), present=present)
    assert len(run) == 20 and p.health()["counters"]["samples_absent"] == 1
    assert run.attitude_frame().shape == (20, 21)  # replay's 11 + 3 + N + 3 columns, gyros as the mask


def test_scenario_and_campaign_attributes(tmp_path):
    sc = tetra.scenario("orbit", duration_s=30.0)
    assert sc.duration_s == 30.0 and not sc.closed_loop and sc.unit.gyro_count == 4
    spec = tetra.campaign_spec({"scenarios": ["static"], "loop": "open", "duration_s": 30, "kinds": ["stuck"],
                                "gyros": [4], "onsets_s": [10], "seeds": [1, 2]})
    assert spec.runs == 2 and not spec.closed_loop and spec.in_process and spec.scenario_paths == ["static"]
    with pytest.raises(tetra.BadInputError):
        tetra.scenario({"scenario": "static", "unit": "missing_unit.yaml"}, base_dir=tmp_path)


def test_score_arrays(orbit_fault_files):
    s = tetra.score(str(orbit_fault_files / "att.csv"), str(orbit_fault_files / "truth.csv"))
    m = len(s.time_s)
    assert s.error_B_deg.shape == (m, 3) and s.sigma_B_deg.shape == (m, 3) and s.sigma_deg.shape == (m,)
    assert s.per_axis_sigma and s.nees_dof == 3 and s.within_B.shape == (3, 3)
    assert 0.0 <= s.within_total[0] <= s.within_total[2] <= 1.0
