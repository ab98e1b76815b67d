"""tetra.sim against `tetra sim`: the same log and truth, bit for bit."""
import json

import numpy as np
import pytest

import tetra
from conftest import ORBIT_FAULT, read_csv_exact, same_bits


def test_sim_equals_the_command(orbit_fault_files):
    d = orbit_fault_files
    run = tetra.sim(ORBIT_FAULT, seed=4)
    cli = tetra.read_gyro_log(str(d / "log.csv"))
    assert run.log.gyro_count == cli.gyro_count == 4 and not run.log.units_dps
    assert same_bits(run.log.time_s, cli.time_s)
    assert same_bits(run.log.values, cli.values)
    assert np.array_equal(run.log.present, cli.present)
    assert same_bits(run.log.reference_wxyz, cli.reference_wxyz)
    assert np.array_equal(run.log.reference_present, cli.reference_present)
    truth = read_csv_exact(d / "truth.csv")
    frame = tetra.truth_frame(run.truth)
    assert list(frame.columns) == list(truth.columns)
    for c in truth.columns:
        assert same_bits(frame[c].to_numpy(), truth[c].to_numpy()), c


def test_scenario_from_file_name_and_dict_agree(orbit_fault_files):
    a = tetra.sim(str(orbit_fault_files / "scenario.yaml"), seed=4)
    b = tetra.sim(ORBIT_FAULT, seed=4)
    assert same_bits(a.log.values, b.log.values)


def test_builtin_scenarios_and_overrides():
    assert "static" in tetra.builtin_scenarios()
    run = tetra.sim("static", duration_s=2.0, rate_hz=50.0, seed=1)
    assert len(run.log) == 100 and run.truth.q_RB_wxyz.shape == (100, 4)
    assert run.log.reference_wxyz is None
    frame = tetra.log_frame(run.log)
    assert list(frame.columns) == ["time_s", "g1", "g2", "g3", "g4"]


def test_scenario_errors():
    with pytest.raises(tetra.BadInputError, match="bogus"):
        tetra.sim({"scenario": "static", "bogus": 1})
    with pytest.raises(tetra.BadInputError):
        tetra.sim("static", duration_s=-1.0)
    with pytest.raises(tetra.BadInputError, match="nowhere"):
        tetra.sim("/nowhere/scenario.yaml")
    with pytest.raises(TypeError):
        tetra.sim({"scenario": "static", "duration_s": object()})
