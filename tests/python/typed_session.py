"""A typed session over the package's stubs (ctest python_stubs: mypy --strict): every call the docs show,
with the types the stubs promise, so that a stub out of step with the package fails here."""
import pathlib
from typing import Optional

import numpy as np
import numpy.typing as npt

import tetra


def session(examples: pathlib.Path) -> float:
    cal: tetra.Calibration = tetra.Calibration.read(examples / "seed_unit.yaml")
    cal.write(pathlib.Path("cal.yaml"))
    log: tetra.GyroLog = tetra.read_gyro_log(examples / "static.csv")
    seen: list[tuple[int, int]] = []
    run: tetra.SimRun = tetra.sim("static", duration_s=60.0, seed=2, progress=lambda d, t: seen.append((d, t)))
    curves = tetra.allan(run.log.values[:, 0], rate=10.0, taus="octave")
    assert isinstance(curves, tetra.AllanResult)
    taus, devs, errs, ns = tetra.oadev(run.log.values[:, 0], rate=10.0, data_type="freq", taus=[1.0, 2.0])
    also = tetra.allan.oadev(run.log.values[:, 0], rate=10.0)
    adev: npt.NDArray[np.float64] = curves.adev
    p = tetra.Pipeline(cal, {"latitude_deg": 45.0})
    out: tetra.PipelineRun = p.run_log(log, progress=None)
    health = p.health()
    frame = out.attitude_frame()
    score: tetra.AttitudeScore = tetra.score(frame, run)
    rows: tetra.CampaignResult = tetra.campaign(examples / "campaign.yaml", runs=[0], jobs=2)
    none: Optional[float] = cal.latitude_deg
    return float(adev[0] + devs[0] + errs[0] + ns[0] + taus[0] + also[1][0]) + score.rms_total_deg + len(rows) \
        + len(health) + (none or 0.0) + len(seen)


def dds_session(log: tetra.GyroLog) -> float:
    """tetra.dds as docs/python.md "DDS" uses it (checked by mypy only: it needs a service)."""
    import tetra.dds as dds
    sub = dds.Subscriber("tetra-1", domain=7)
    with dds.Lockstep("tetra-1", gyros=4, rate_hz=100.0, domain=7) as lock:
        a: dds.Attitude = lock.step(float(log.time_s[0]), log.values[0], log.present[0], None, timeout_s=2.0)
    tracker = dds.ReferencePublisher("tetra-1", domain=7, timeout_s=1.0)
    tracker.send(a.stamp_ns, a.q_RB_wxyz)
    h: dds.Health = sub.wait_health(1.0, lambda h: h.reference_state == "accepted")
    e: dds.FdiEvent = dds.command("tetra-1", "exclude", 2, force=False, domain=7, timeout_s=1.0)
    n: int = sub.poll(0.1)
    return float(a.sigma_rad[0]) + h.reference_nis + e.statistic + n + len(sub.events)
