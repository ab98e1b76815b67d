"""Python conventions (docs/python.md): os.PathLike paths, warnings, allantools' oadev, masks, run ids,
score() of DataFrames, read-only copies, docstrings and named parameters."""
import inspect
import pathlib
import warnings

import numpy as np
import pytest

import tetra
from conftest import EXAMPLES


def test_pathlib_paths_everywhere(tmp_path):
    cal = tetra.Calibration.read(EXAMPLES / "seed_unit.yaml")
    cal.write(tmp_path / "cal.yaml")
    assert tetra.Calibration.read(tmp_path / "cal.yaml").to_yaml() == cal.to_yaml()
    run = tetra.sim("static", duration_s=20)
    path = tmp_path / "log.csv"
    path.write_text("time_s,g1,g2,g3,g4\n" + "".join(
        f"{t!r},{','.join(repr(v) for v in row)}\n" for t, row in zip(run.log.time_s, run.log.values)))
    log = tetra.read_gyro_log(path)
    assert len(log) == len(run.log)
    assert tetra.allan_log(path, calibration=cal).gyros
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # seed_unit.yaml states its noise: no warning
        assert tetra.Pipeline(pathlib.Path(EXAMPLES / "seed_unit.yaml")).gyro_count == 4


def test_the_default_noise_warning_is_a_python_warning():
    bare = tetra.Calibration.from_arrays([0.02] * 4, [0.0] * 4, tetra.Calibration.seed_unit().axes_B)
    with pytest.warns(tetra.DefaultNoiseWarning, match="noise") as record:
        tetra.Pipeline(bare)
    assert record[0].filename == __file__  # stacklevel: the caller's line
    with warnings.catch_warnings():
        warnings.simplefilter("error", tetra.DefaultNoiseWarning)
        with pytest.raises(tetra.DefaultNoiseWarning):
            tetra.Pipeline(bare)


def allantools_oadev(data, rate, data_type, taus):
    """allantools' oadev (tau_generator, calc_adev_phase, remove_small_ns) for the comparison."""
    if data_type == "freq":
        y = data - np.nanmean(data)
        phase = np.insert(np.cumsum(y) / rate, 0, 0.0)
    else:
        phase = np.asarray(data, dtype=float)
    n = len(phase)
    if taus is None or taus == "octave":
        taus = (1.0 / rate) * np.logspace(0, int(np.floor(np.log2(n))), int(np.floor(np.log2(n))) + 1, base=2.0)
    m = np.round(np.asarray(taus) * rate)
    m = np.unique(m[(m < n) & (m > 0)])
    out = []
    for mj in m.astype(int):
        if n - 2 * mj < 1:
            continue
        d = phase[2 * mj:] - 2 * phase[mj:n - mj] + phase[:n - 2 * mj]
        k = len(d)
        if k > 1:
            dev = np.sqrt(np.sum(d * d) / (2.0 * k)) / mj * rate
            out.append((mj / rate, dev, dev / np.sqrt(k), k))
    return tuple(np.array(c, dtype=float) for c in zip(*out))


@pytest.mark.parametrize("data_type", ["freq", "phase"])
@pytest.mark.parametrize("taus", [None, "octave", [0.1, 0.5, 2.0, 7.3]])
def test_oadev_is_allantools_oadev(data_type, taus):
    rng = np.random.default_rng(5)
    data = rng.standard_normal(5000) + 3.0
    if data_type == "phase":
        data = np.cumsum(data) * 0.1
    got = tetra.oadev(data, rate=10.0, data_type=data_type, taus=taus)
    want = allantools_oadev(data, 10.0, data_type, taus)
    assert tetra.allan.oadev is tetra.oadev
    assert len(got) == 4
    for g, w in zip(got, want):
        np.testing.assert_allclose(g, w, rtol=1e-9)
    with pytest.raises(ValueError, match="data_type"):
        tetra.oadev(data, rate=10.0, data_type="angle")


def test_allan_takes_the_sampling_rate_and_keeps_its_api():
    y = np.random.default_rng(6).standard_normal(2000)
    by_rate = tetra.allan(y, rate=10)
    by_interval = tetra.allan(y, 0.1)
    assert np.array_equal(by_rate.adev, by_interval.adev)
    assert np.array_equal(tetra.allan(rate=y, tau0_s=0.1).adev, by_interval.adev)  # the old keyword
    with pytest.raises(TypeError, match="tau0_s"):
        tetra.allan(y)


def test_a_1d_present_applies_to_every_series_and_any_nonzero_is_present():
    y = np.random.default_rng(7).standard_normal((3000, 2))
    present = np.ones(3000, dtype=bool)
    present[1000:1100] = False
    one = tetra.allan(y, 0.1, present=present)
    both = tetra.allan(y, 0.1, present=np.repeat(present[:, None], 2, axis=1))
    assert [r.present_samples for r in one] == [2900, 2900]
    assert np.array_equal(one[1].adev, both[1].adev)
    as_int = present.astype(np.int64) * 256  # 256 wrapped to 0 (absent) in a uint8 cast
    assert tetra.allan(y[:, 0], 0.1, present=as_int).present_samples == 2900
    with pytest.raises(ValueError, match="present"):
        tetra.allan(y, 0.1, present=np.ones(10))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tetra.DefaultNoiseWarning)
        p = tetra.Pipeline(tetra.Calibration.seed_unit())
    log = tetra.sim("static", duration_s=10).log
    a = p.run(log.time_s, log.values, log.present.astype(np.int64) * 256)
    p.reset()
    b = p.run(log.time_s, log.values, log.present)
    assert np.array_equal(a.q_RB_wxyz, b.q_RB_wxyz)


def test_campaign_runs_are_each_given_once():
    spec = {"scenarios": ["static"], "loop": "open", "duration_s": 20, "kinds": ["bias"], "sizes": {"bias": [0.01]},
            "gyros": [1], "onsets_s": [10], "seeds": [1]}
    with pytest.raises(ValueError, match="run 0 is given twice"):
        tetra.campaign(spec, runs=[0, 0, 0])


def test_score_takes_the_frames_it_makes():
    orbit = tetra.sim({"scenario": "orbit", "duration_s": 60, "reference": {"rate_hz": 1, "noise_arcsec": 5}},
                      seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tetra.DefaultNoiseWarning)
        run = tetra.Pipeline(tetra.Calibration.seed_unit()).run_log(orbit.log)
    direct = tetra.score(run, orbit)
    framed = tetra.score(run.attitude_frame(), tetra.truth_frame(orbit.truth))
    assert framed.rms_total_deg == direct.rms_total_deg and framed.mean_nees == direct.mean_nees
    assert framed.per_axis_sigma
    with pytest.raises(ValueError, match="qw"):
        tetra.score(run.attitude_frame().drop(columns=["qw"]), orbit)


def test_arrays_that_are_copies_are_read_only():
    cal = tetra.Calibration.seed_unit()
    with pytest.raises(ValueError, match="read-only"):
        cal.scale_factor_V_per_dps[0] = 1.0
    for a in (cal.bias_V, cal.axes_B):
        assert not a.flags.writeable
    r = tetra.allan(np.random.default_rng(1).standard_normal(1000), 0.1)
    assert not r.adev.flags.writeable and not r.tau_s.flags.writeable
    log = tetra.sim("static", duration_s=5).log
    assert log.values.flags.writeable  # the log's own arrays: writing changes them
    result = tetra.calibrate(EXAMPLES / "turntable.csv")
    result.calibration.unit = "renamed"  # the result's own calibration, not a copy that forgets it
    assert result.calibration.unit == "renamed"


def test_every_public_field_has_a_docstring_and_the_module_names_its_parameters():
    undocumented = []
    for cls in (tetra.AttitudeScore, tetra.AllanResult, tetra.NoiseFit, tetra.GyroLog, tetra.Calibration,
                tetra.CalibrationResult, tetra.Truth, tetra.SimRun, tetra.Scenario, tetra.CampaignSpec,
                tetra.LogAllan, tetra.GyroAllan, tetra.PipelineConfig):
        for name, attr in vars(cls).items():
            if not name.startswith("_") and isinstance(attr, property) and not (attr.__doc__ or "").strip():
                undocumented.append(f"{cls.__name__}.{name}")
    assert not undocumented, undocumented
    assert "TDMS" in tetra.read_gyro_log.__doc__
    for name, f in vars(tetra._tetra._Pipeline).items():
        if callable(f) and f.__doc__:
            assert "arg0" not in f.__doc__, (name, f.__doc__)
    assert "os.PathLike" in tetra.read_gyro_log.__doc__
    assert "progress" in inspect.signature(tetra.Pipeline.run).parameters
