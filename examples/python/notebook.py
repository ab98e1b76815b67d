# %% [markdown]
# # tetra from Python: calibrate, characterise the noise, fuse, score, run a campaign
#
# A notebook as a plain Python file: each `# %%` is a cell (Jupyter, VS Code and Spyder run them one by
# one); `python3 examples/python/notebook.py` runs it whole and headless, writing the plots as PNG files
# into `--out` (default `notebook_out/`). docs/python.md describes the package.

# %%
import argparse
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")  # headless; drop this line in a notebook
import matplotlib.pyplot as plt
import numpy as np

import tetra

here = pathlib.Path(__file__).resolve().parent
parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--out", default="notebook_out", help="folder for the plots")
args, _ = parser.parse_known_args(sys.argv[1:])
out = pathlib.Path(args.out)
out.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## 1. Calibrate from a turntable log
# The 16-sequence plan of the seed paper, simulated for the seed's unit (`tetra sim turntable`); the
# calibration file it gives is what `tetra calibrate` writes. With the unit's noise model (`noise=`) the
# 1-sigma include its bias instability (docs/calibration.md, "Are the 1σ honest?").

# %%
truth_unit = tetra.Calibration.seed_unit()
turntable = tetra.simulate_turntable(truth_unit, rate_hz=2.0, seed=1)
calibrated = tetra.calibrate(turntable, method="sixteen", noise=truth_unit)
cal = calibrated.calibration
print("scale factor [V/(deg/s)]:", np.round(cal.scale_factor_V_per_dps, 6))
print("error / 1-sigma:", np.round((cal.scale_factor_V_per_dps - truth_unit.scale_factor_V_per_dps)
                                    / cal.sigma_scale_factor_V_per_dps, 2))

# %% [markdown]
# ## 2. Characterise the noise (Allan deviation)
# Twenty minutes of a unit at rest at 10 Hz; the rates in deg/s from the calibration.

# %%
rest = tetra.sim("static", duration_s=1200.0, seed=2)
rates_dps = (rest.log.values - cal.bias_V) / cal.scale_factor_V_per_dps
curves = tetra.allan(rates_dps, 0.1)
fig, ax = plt.subplots()
for i, c in enumerate(curves):
    ax.loglog(c.tau_s, c.adev, label=f"gyro {i + 1}")
    ax.fill_between(c.tau_s, c.adev_lo, c.adev_hi, alpha=0.2)
ax.set_xlabel("tau [s]")
ax.set_ylabel("Allan deviation [deg/s]")
ax.legend()
fig.savefig(out / "allan.png", dpi=80)
print("angle random walk N [deg/sqrt(s)]:", [f"{c.fit.value['N']:.2e}" for c in curves])

# %% [markdown]
# ## 3. Fuse a simulated orbit with a fault, score against the truth
# `Pipeline.run` runs every epoch in C++ (no Python per epoch).

# %%
orbit = tetra.sim({"scenario": "orbit", "duration_s": 300, "rate_hz": 10,
                   "reference": {"rate_hz": 1, "noise_arcsec": 5},
                   "faults": ["gyro=2,kind=bias,at=100,size=0.01"]}, seed=3)
run = tetra.Pipeline(cal).run_log(orbit.log)
for e in run.events:
    if e["type"] in ("detected", "isolated"):
        print(f"{e['time_s']:8.1f} s  {e['type']:9s} gyro {e['gyro']}  {e['kind']}")
s = tetra.score(run, orbit)
print(f"attitude error: RMS {s.rms_total_deg * 3600:.1f} arcsec, NEES mean {s.mean_nees:.2f} (3 expected)")
fig, ax = plt.subplots()
for a, name in enumerate("xyz"):
    ax.plot(s.time_s, s.error_B_deg[:, a] * 3600, label=f"e_{name}")
ax.plot(s.time_s, 3 * s.sigma_deg * 3600, "k--", label="3 sigma")
ax.set_xlabel("time [s]")
ax.set_ylabel("error [arcsec]")
ax.legend()
fig.savefig(out / "attitude_error.png", dpi=80)

# %% [markdown]
# ## 4. A small fault-injection campaign
# Bias steps on each gyro of an open-loop rest, and one fault-free run: the rows as a DataFrame.

# %%
result = tetra.campaign({"scenarios": ["static"], "loop": "open", "duration_s": 60, "kinds": ["bias"],
                         "sizes": {"bias": [0.005]}, "gyros": [1, 2, 3, 4], "onsets_s": [20], "seeds": [1],
                         "fault_free": True})
rows = result.rows
print(rows[["run", "kind", "gyro", "outcome", "detection_delay_s", "isolation_delay_s"]].to_string(index=False))
faulty = rows[rows["kind"] != "none"]
fig, ax = plt.subplots()
ax.bar(faulty["gyro"].astype(str), faulty["isolation_delay_s"])
ax.set_xlabel("faulty gyro")
ax.set_ylabel("isolation delay [s]")
fig.savefig(out / "campaign_delays.png", dpi=80)
print("plots in", out)
