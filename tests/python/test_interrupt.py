"""Ctrl-C and progress in the long calls (docs/python.md, "Ctrl-C, progress and threads").

Each long call runs in a child interpreter; SIGINT is sent a second into the call and the time to the
child's KeyboardInterrupt is measured from the parent (the signal sent, the child's line read). Before the
calls polled for signals, a KeyboardInterrupt came only when the call returned (tens of seconds here)."""
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import tetra
from conftest import EXAMPLES

# A campaign of 160 open-loop runs of an hour at 10 Hz: about 25 s on one core.
LONG_CAMPAIGN = {"scenarios": ["static"], "loop": "open", "duration_s": 3600, "kinds": ["bias"],
                 "sizes": {"bias": [0.01]}, "gyros": [1, 2, 3, 4], "onsets_s": [300],
                 "seeds": list(range(1, 41))}

PRELUDE = """
import sys, time, warnings
import numpy as np
import tetra
warnings.simplefilter("ignore", tetra.DefaultNoiseWarning)
LONG_CAMPAIGN = %r
def long_log():
    n = 4_000_000  # 11 hours at 100 Hz: seconds of Pipeline.run
    rng = np.random.default_rng(1)
    cal = tetra.Calibration.seed_unit()
    raw = cal.bias_V + 1e-4 * rng.standard_normal((n, cal.gyro_count))
    return cal, 0.01 * np.arange(n), raw
""" % (LONG_CAMPAIGN,)

CALLS = {
    "Pipeline.run": ("cal, t, raw = long_log()\np = tetra.Pipeline(cal)", "p.run(t, raw)"),
    "Pipeline.run_log": ("log = tetra.sim('static', duration_s=3600, rate_hz=100).log\n"
                         "p = tetra.Pipeline(tetra.Calibration.seed_unit())\nlogs = [log] * 400",
                         "[p.run_log(l) for l in logs]"),
    "sim": ("", "tetra.sim('static', duration_s=60000, rate_hz=100)"),
    # SIGINT a quarter of the way through the averaging times (the whole call takes about 1 s: a fixed
    # second could come after it returned).
    "allan": ("y = np.random.default_rng(2).standard_normal(85_000)\nsaid = []\n"
              "def told(d, t):\n    if 4 * d >= t and not said:\n"
              "        said.append(print('intervals', flush=True))",
              "tetra.allan(y, 0.01, taus='all', progress=told)"),
    # SIGINT once every averaging time is done, while the intervals' chi-square quantiles run.
    "allan, in the intervals": ("y = np.random.default_rng(2).standard_normal(85_000)\nsaid = []\n"
                                "def told(d, t):\n    if d == t and not said:\n"
                                "        said.append(print('intervals', flush=True))",
                                "tetra.allan(y, 0.01, taus='all', progress=told)"),
    "campaign": ("", "tetra.campaign(LONG_CAMPAIGN)"),
    "campaign jobs=2": ("", "tetra.campaign(LONG_CAMPAIGN, jobs=2)"),
}


def interrupt_after(setup, call, delay_s=1.0):
    """Runs `call` in a child, sends SIGINT `delay_s` into it (or 50 ms after the child's line 'intervals'
    when its progress callable prints one): (seconds to the KeyboardInterrupt, the child's report line)."""
    child = textwrap.dedent(PRELUDE) + setup + f"""
print("ready", flush=True)
t0 = time.monotonic()
try:
    {call}
    print("finished %.3f" % (time.monotonic() - t0), flush=True)
except KeyboardInterrupt as e:
    partial = getattr(e, "partial", None)
    print("interrupted", "none" if partial is None else len(partial), flush=True)
"""
    p = subprocess.Popen([sys.executable, "-c", child], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "ready"
        if "intervals" in setup:
            assert p.stdout.readline().strip() == "intervals"
            delay_s = 0.05
        time.sleep(delay_s)
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        line = p.stdout.readline().strip()
        latency = time.monotonic() - sent
        assert p.wait(timeout=30) == 0
        return latency, line
    finally:
        if p.poll() is None:
            p.kill()


@pytest.mark.parametrize("name", list(CALLS))
def test_ctrl_c_stops_a_long_call_within_0_2_s(name):
    setup, call = CALLS[name]
    latency, line = interrupt_after(setup, call)
    print(f"{name}: KeyboardInterrupt {1000 * latency:.0f} ms after SIGINT")
    assert line.startswith("interrupted"), line
    assert latency < 0.2, f"{name}: {latency:.3f} s"


def test_an_interrupted_campaign_keeps_the_rows_done():
    latency, line = interrupt_after("", "tetra.campaign(LONG_CAMPAIGN)", delay_s=2.0)
    print(f"campaign, SIGINT 2 s in: KeyboardInterrupt {1000 * latency:.0f} ms after SIGINT, {line}")
    assert latency < 0.2, f"{latency:.3f} s"
    done = int(line.split()[1])
    assert 0 < done < tetra.campaign_spec(LONG_CAMPAIGN).runs, line


def test_progress_callable_and_tqdm_like_bar():
    seen = []
    run = tetra.sim("static", duration_s=600, rate_hz=100, progress=lambda d, t: seen.append((d, t)))
    assert seen[-1] == (len(run.log), len(run.log))
    assert all(b[0] >= a[0] for a, b in zip(seen, seen[1:]))

    class Bar:  # what tqdm offers: total, update(n), refresh()
        total = None
        n = 0

        def update(self, k):
            self.n += k

        def refresh(self):
            pass

    bar = Bar()
    p = tetra.Pipeline(tetra.Calibration.read(EXAMPLES / "seed_unit.yaml"))
    out = p.run_log(run.log, progress=bar)
    assert bar.total == len(run.log) == bar.n and out.epochs == len(run.log)
    spec = {**LONG_CAMPAIGN, "duration_s": 30, "onsets_s": [10], "seeds": [1]}
    steps = []
    tetra.campaign(spec, progress=lambda d, t: steps.append((d, t)))
    assert steps[-1] == (4, 4)
    with pytest.raises(TypeError, match="progress"):
        tetra.sim("static", duration_s=10, progress=3)


def test_allan_progress_runs_over_every_series():
    seen = []
    tetra.allan(np.random.default_rng(3).standard_normal((2000, 3)), 0.1, progress=lambda d, t: seen.append((d, t)))
    total = seen[-1][1]
    assert seen[-1][0] == total and total % 3 == 0 and all(t == total for _, t in seen)


def test_progress_with_tqdm():
    tqdm = pytest.importorskip("tqdm")
    bar = tqdm.tqdm(total=None, disable=False, mininterval=0)
    run = tetra.sim("static", duration_s=600, rate_hz=100, progress=bar)
    assert bar.total == bar.n == len(run.log)
    bar.close()
    tetra.sim("static", duration_s=60, progress=tqdm.tqdm)  # the class: a bar of the call's own


def test_an_exception_in_the_progress_callback_stops_the_call():
    def fail(done, total):
        raise ZeroDivisionError("from the callback")
    with pytest.raises(ZeroDivisionError, match="from the callback"):
        tetra.sim("static", duration_s=3600, rate_hz=100, progress=fail)


def test_campaign_jobs_gives_the_same_rows():
    spec = {**LONG_CAMPAIGN, "duration_s": 30, "onsets_s": [10], "seeds": [1, 2]}
    one = tetra.campaign(spec)
    assert tetra.campaign(spec, jobs=3).csv == one.csv
    assert tetra.campaign(spec, jobs=64, runs=[5, 1]).csv.splitlines()[1:] == [one.csv.splitlines()[6],
                                                                              one.csv.splitlines()[2]]
    with pytest.raises(ValueError, match="jobs"):
        tetra.campaign(spec, jobs=0)
