"""One Pipeline from two threads (docs/python.md, "Threads"): a clear RuntimeError, never a crash.

Before the guard, a second run on a Pipeline while a first ran with the GIL released freed the same
buffers twice (the interpreter died, exit 134 or 139) or gave silently wrong rows."""
import threading
import warnings

import numpy as np
import pytest

import tetra


@pytest.fixture(scope="module")
def log():
    return tetra.sim("static", duration_s=1200, rate_hz=100, seed=3).log


def pipeline():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tetra.DefaultNoiseWarning)
        return tetra.Pipeline(tetra.Calibration.seed_unit())


def test_a_second_thread_gets_a_runtime_error_and_the_first_run_is_intact(log):
    p = pipeline()
    inside = threading.Event()
    release = threading.Event()
    result = {}

    def progress(done, total):
        inside.set()
        release.wait(10)

    def first():
        result["run"] = p.run_log(log, progress=progress)

    t = threading.Thread(target=first)
    t.start()
    assert inside.wait(10)
    try:
        for call in (lambda: p.run_log(log), lambda: p.step(0.0, np.zeros(4)), p.health, p.reset,
                     lambda: p.exclude(1, 0)):
            with pytest.raises(RuntimeError, match="in use: Pipeline.run is running on it"):
                call()
    finally:
        release.set()
        t.join()
    alone = pipeline().run_log(log)
    assert np.array_equal(result["run"].q_RB_wxyz, alone.q_RB_wxyz)
    assert p.health()["mode"] in tetra.MODE_NAMES  # free again once the run is over


def test_two_threads_hammering_one_pipeline_never_crash(log):
    p = pipeline()
    errors, runs = [], []

    def worker():
        for _ in range(5):
            try:
                runs.append(p.run_log(log))
            except RuntimeError as e:
                errors.append(str(e))

    threads = [threading.Thread(target=worker) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(runs) + len(errors) == 10 and runs
    assert all("in use" in e for e in errors)


def test_the_progress_callback_cannot_reenter_its_pipeline(log):
    p = pipeline()
    seen = []

    def progress(done, total):
        try:
            p.health()
        except RuntimeError as e:
            seen.append(str(e))

    p.run_log(log, progress=progress)
    assert seen and "progress callback" in seen[0]


def test_separate_pipelines_run_in_parallel_threads(log):
    out = [None, None]

    def work(i):
        out[i] = pipeline().run_log(log)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert np.array_equal(out[0].q_RB_wxyz, out[1].q_RB_wxyz)
