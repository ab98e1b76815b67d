"""tetra.score against `tetra score --json`."""
import json

import numpy as np
import pytest

import tetra
from conftest import EXAMPLES, ORBIT_FAULT


def _figures(s):
    return {
        "rms_xyz": list(s.rms_B_deg), "rms_total": s.rms_total_deg, "max_abs_xyz": list(s.max_abs_B_deg),
        "max_total": s.max_total_deg, "final_total": s.final_total_deg, "mean": s.mean_nees,
        "estimate": s.angle_axis_deg, "truth": s.truth_angle_axis_deg,
    }


def test_score_equals_the_command(orbit_fault_files):
    d = orbit_fault_files
    cli = json.loads((d / "score.json").read_text())
    expected = {
        "rms_xyz": cli["error_deg"]["rms_xyz"], "rms_total": cli["error_deg"]["rms_total"],
        "max_abs_xyz": cli["error_deg"]["max_abs_xyz"], "max_total": cli["error_deg"]["max_total"],
        "final_total": cli["error_deg"]["final_total"], "mean": cli["nees"]["mean"],
        "estimate": cli["integrated_angle_deg"]["estimate"], "truth": cli["integrated_angle_deg"]["truth"],
    }
    from_files = tetra.score(str(d / "att.csv"), str(d / "truth.csv"))
    assert _figures(from_files) == expected
    assert from_files.exact_matches == cli["epochs"]["exact"]
    # The same from the arrays: the run and the simulated truth in memory.
    cal = tetra.Calibration.read(str(EXAMPLES / "seed_unit.yaml"))
    sim = tetra.sim(ORBIT_FAULT, seed=4)
    run = tetra.Pipeline(cal).run_log(sim.log)
    assert _figures(tetra.score(run, sim)) == expected
    assert from_files.error_B_deg.shape == (len(run), 3)


def test_score_errors(orbit_fault_files):
    d = orbit_fault_files
    with pytest.raises(tetra.BadInputError, match="axis_B"):
        tetra.score(str(d / "att.csv"), str(d / "truth.csv"), axis_B=(0, 0, 2))
    with pytest.raises(ValueError, match="time not increasing"):
        tetra.score({"time_s": [1.0, 0.5], "q_RB_wxyz": [[1, 0, 0, 0]] * 2, "omega_BR_B_dps": [[0, 0, 0]] * 2,
                     "sigma_deg": [1, 1]}, str(d / "truth.csv"))
    with pytest.raises(TypeError):
        tetra.score(42, str(d / "truth.csv"))
