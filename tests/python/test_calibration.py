"""tetra.Calibration and tetra.calibrate against `tetra calibrate`."""
import numpy as np
import pytest

import tetra
from conftest import EXAMPLES, same_bits, without_comments


def test_read_and_round_trip(tmp_path):
    cal = tetra.Calibration.read(str(EXAMPLES / "seed_unit.yaml"))
    assert cal.gyro_count == 4
    assert cal.axes_B.shape == (4, 3)
    assert cal.noise[0]["arw_dps_rtHz"] == 3e-05
    again = tetra.Calibration.from_yaml(cal.to_yaml())
    assert same_bits(again.scale_factor_V_per_dps, cal.scale_factor_V_per_dps)
    assert same_bits(again.axes_B, cal.axes_B)
    cal.write(str(tmp_path / "c.yaml"))
    assert tetra.Calibration.read(str(tmp_path / "c.yaml")).to_yaml() == cal.to_yaml()


def test_from_arrays_and_its_checks():
    seed = tetra.Calibration.seed_unit()
    cal = tetra.Calibration.from_arrays(seed.scale_factor_V_per_dps, seed.bias_V, seed.axes_B, unit="u")
    # axes normalized again, as the file reader does: within 2 ulp of 1 (|h| components below 1)
    assert np.allclose(cal.axes_B, seed.axes_B, rtol=0, atol=4.5e-16)
    with pytest.raises(tetra.BadInputError):
        tetra.Calibration.from_arrays(seed.scale_factor_V_per_dps, seed.bias_V, 2 * seed.axes_B)
    with pytest.raises(ValueError, match="axes_B"):
        tetra.Calibration.from_arrays(seed.scale_factor_V_per_dps, seed.bias_V, seed.axes_B[:, :2])


def test_bad_file_names_file_and_line():
    with pytest.raises(tetra.BadInputError, match=r"mine\.yaml:\d+"):
        tetra.Calibration.from_yaml("unit: x\nbogus: 1\n", "mine.yaml")
    with pytest.raises(tetra.BadInputError, match="nowhere.yaml"):
        tetra.Calibration.read("/nowhere.yaml")


def test_calibrate_file_equals_the_command(tmp_path, run_cli):
    log = EXAMPLES / "turntable.csv"
    run_cli("calibrate", log, "-o", tmp_path / "cal.yaml")
    r = tetra.calibrate(str(log))
    assert r.latitude_deg == -23.2 and r.sequences == 16
    assert without_comments(r.calibration.to_yaml()) == without_comments((tmp_path / "cal.yaml").read_text())
    assert r.sequence_residual_V.shape == (16, 4)
    assert r.calibration.sigma_bias_V is not None


def test_calibrate_arrays_equals_the_command_on_the_same_log(tmp_path, run_cli):
    tt = tetra.simulate_turntable(rate_hz=2.0, seed=3)
    (tmp_path / "tt.csv").write_text(tt["text"])
    run_cli("calibrate", tmp_path / "tt.csv", "--method", "batch", "-o", tmp_path / "cal.yaml")
    r = tetra.calibrate(tt, method="batch", unit="seed-as-built")
    assert without_comments(r.calibration.to_yaml()) == without_comments((tmp_path / "cal.yaml").read_text())
    assert tt["g_V"].flags.c_contiguous and tt["g_V"].dtype == np.float64  # read in place


def test_calibrate_errors(tmp_path):
    tt = tetra.simulate_turntable(rate_hz=2.0)
    with pytest.raises(ValueError, match="method"):
        tetra.calibrate(tt, method="other")
    with pytest.raises(ValueError, match="bias_model"):
        tetra.calibrate(tt, method="batch", bias_model="seed")
    bad = dict(tt)
    bad["g_V"] = tt["g_V"].copy()
    bad["g_V"][5, 2] = np.nan
    with pytest.raises(ValueError, match=r"g_V\[5, 2\]: NaN"):
        tetra.calibrate(bad)
    with pytest.raises(ValueError, match="g_V"):
        tetra.calibrate({**tt, "g_V": tt["g_V"][:10]})
    with pytest.raises(ValueError, match="missing arrays"):
        tetra.calibrate({"time_s": tt["time_s"]})
    with pytest.raises(tetra.BadInputError, match="missing.csv"):
        tetra.calibrate(str(tmp_path / "missing.csv"))
