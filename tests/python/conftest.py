"""Shared by the pytest tests of the Python package (ctest python_tests; docs/python.md).

The tests run the built `tetra` program on the same inputs as the bindings and compare the outputs to the
last bit. TETRA_BIN names the program (ctest sets it); TETRA_SOURCE_DIR the source tree (for examples/).
"""
import io
import json
import os
import pathlib
import subprocess

import numpy as np
import pandas as pd
import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("TETRA_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
EXAMPLES = SOURCE_DIR / "examples"

# A 2-minute orbit with a star tracker and a gyro-2 bias step at 40 s: events, references, every column.
ORBIT_FAULT = {
    "scenario": "orbit",
    "duration_s": 120,
    "rate_hz": 10,
    "acs": {"amplitude_deg": 0.05, "peak_accel_dps2": 1.0e-5},
    "reference": {"rate_hz": 1, "noise_arcsec": 5},
    "faults": ["gyro=2,kind=bias,at=40,size=0.01"],
}


@pytest.fixture(scope="session")
def tetra_bin():
    path = os.environ.get("TETRA_BIN")
    if not path:
        pytest.skip("TETRA_BIN is not set (ctest sets it)")
    return path


@pytest.fixture(scope="session")
def run_cli(tetra_bin):
    def run(*args, cwd=None):
        r = subprocess.run([tetra_bin, *map(str, args)], cwd=cwd, capture_output=True, text=True)
        assert r.returncode == 0, f"tetra {' '.join(map(str, args))}: {r.stderr}"
        return r
    return run


def read_csv_exact(path):
    """A CSV written by tetra (shortest round-trip numbers) read back to the same doubles."""
    return pd.read_csv(path, comment="#", float_precision="round_trip")


def without_comments(text):
    return "".join(line for line in io.StringIO(text) if not line.startswith("#"))


def same_bits(a, b):
    """Equal arrays, NaN where NaN, bit for bit (0.0 and -0.0 differ)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


@pytest.fixture(scope="session")
def orbit_fault_files(tmp_path_factory, run_cli):
    """ORBIT_FAULT simulated by `tetra sim` (seed 4) and replayed by `tetra replay` with the seed unit."""
    d = tmp_path_factory.mktemp("orbit_fault")
    spec = d / "scenario.yaml"
    spec.write_text(json.dumps(ORBIT_FAULT))
    run_cli("sim", spec, "--seed", 4, "--out", d / "log.csv", "--truth", d / "truth.csv")
    cal = EXAMPLES / "seed_unit.yaml"
    run_cli("replay", d / "log.csv", "--calibration", cal, "--attitude", d / "att.csv", "--events", d / "events.jsonl")
    run_cli("score", d / "att.csv", d / "truth.csv", "--json", d / "score.json")
    return d
