"""tetra.allan (arrays) and tetra.allan_log against `tetra allan`."""
import json

import numpy as np
import pytest

import tetra
from conftest import EXAMPLES, same_bits, without_comments


@pytest.fixture(scope="module")
def static_log(tmp_path_factory, run_cli):
    d = tmp_path_factory.mktemp("allan")
    run_cli("sim", "static", "--minutes", 10, "--seed", 2, "--out", d / "log.csv")
    cal = EXAMPLES / "seed_unit.yaml"
    run_cli("allan", d / "log.csv", "--calibration", cal, "--csv", d / "adev.csv", "--json", d / "noise.json")
    return d


def test_allan_log_equals_the_command(static_log):
    cal = tetra.Calibration.read(str(EXAMPLES / "seed_unit.yaml"))
    a = tetra.allan_log(str(static_log / "log.csv"), calibration=cal)
    assert a.units == "deg/s" and len(a.gyros) == 4
    assert a.to_csv() == without_comments((static_log / "adev.csv").read_text())
    cli = json.loads((static_log / "noise.json").read_text())
    for g, c in zip(a.gyros, cli["gyros"]):
        for term, value in g.result.fit.reported.items():
            assert value == c[term]  # JSON numbers in shortest round-trip form: the same doubles


def test_allan_arrays_equal_the_log_analysis(static_log):
    cal = tetra.Calibration.read(str(EXAMPLES / "seed_unit.yaml"))
    log = tetra.read_gyro_log(str(static_log / "log.csv"))
    a = tetra.allan_log(str(static_log / "log.csv"), calibration=cal)
    rates = (log.values - cal.bias_V) / cal.scale_factor_V_per_dps  # the library's (g - bias)/scale
    results = tetra.allan(rates, a.tau0_s)
    assert len(results) == 4
    for r, g in zip(results, a.gyros):
        assert same_bits(r.adev, g.result.adev) and same_bits(r.tau_s, g.result.tau_s)
        assert same_bits(r.adev_lo, g.result.adev_lo) and np.array_equal(r.terms, g.result.terms)
        assert r.fit.value == g.result.fit.value
    one = tetra.allan(np.ascontiguousarray(rates[:, 0]), a.tau0_s, taus=[0.1, 1.0, 10.0])
    assert list(one.tau_s) == pytest.approx([0.1, 1.0, 10.0], rel=1e-12)  # whole multiples of tau0
    assert one.fit.model_adev(one.tau_s).shape == (3,)


def test_allan_gaps_and_errors():
    rng = np.random.default_rng(1)
    y = rng.normal(size=2000)
    present = np.ones(2000, dtype=bool)
    present[100:110] = False
    r = tetra.allan(y, 0.1, present=present)
    assert r.present_samples == 1990
    y2 = y.copy()
    y2[100:110] = np.nan  # NaN counts as not delivered
    assert same_bits(tetra.allan(y2, 0.1).adev, r.adev)
    with pytest.raises(tetra.BadInputError, match="taus"):
        tetra.allan(y, 0.1, taus="fortnightly")
    with pytest.raises(ValueError, match="tau0_s"):
        tetra.allan(y, 0.0)
    with pytest.raises(ValueError, match="present"):
        tetra.allan(y, 0.1, present=present[:10])
    with pytest.raises(ValueError, match="rate"):
        tetra.allan(np.zeros((2, 2, 2)), 0.1)
    with pytest.raises(tetra.BadInputError):
        tetra.allan_log("/no/such/log.csv")
