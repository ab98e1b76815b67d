"""A spacecraft simulator in Python steered by `tetra fusion` over DDS (tetra.dds; docs/python.md, "DDS").

A rigid body (inertia 12, 10, 8 kg m^2) slews 5 deg and holds it, steered by a PD controller (0.05 Hz, damping
0.7, reaction torques up to 0.02 N m) on the attitude and rate tetra estimates from four simulated gyros (the
seed unit of examples/seed_unit.yaml, its noise, gyro 2 biased by 0.01 deg/s from 60 s) and a star tracker
(1 Hz, 5 arcsec). Each epoch goes to the service and its Attitude comes back before the body moves on
(tetra.dds.Lockstep), so the loop is deterministic. Start the service first (examples/dds/closed_loop_fusion.yaml):

    tetra fusion --config examples/dds/closed_loop_fusion.yaml --domain 7 &
    PYTHONPATH=build/python python3 examples/dds/python_closed_loop.py --domain 7 --compare

--compare runs the same loop again with tetra.Pipeline in this process and compares the pointing: equal to the last
bit (tolerance 0), because lockstep hands the service exactly the epochs the in-process pipeline steps, its
attitude comes back as the same doubles, and the body is the same code on the same inputs. Exit 1 otherwise.
"""
import argparse
import json
import os

import numpy as np

import tetra
import tetra.dds

RATE_HZ, SUBSTEPS, REFERENCE_EVERY = 10, 5, 10  # gyro epochs per second, RK4 steps per epoch, epochs per reference
INERTIA = np.array([12.0, 10.0, 8.0])  # [kg m^2] principal moments
WN, ZETA, MAX_TORQUE = 2 * np.pi * 0.05, 0.7, 0.02  # [rad/s], [-], [N m]
DEG = np.pi / 180


def qmul(a, b):
    w1, v1, w2, v2 = a[0], a[1:], b[0], b[1:]
    return np.concatenate([[w1 * w2 - v1 @ v2], w1 * v2 + w2 * v1 + np.cross(v1, v2)])


def qexp(rotation_vector):  # the quaternion of a rotation vector [rad]
    angle = np.linalg.norm(rotation_vector)
    axis = rotation_vector / angle if angle > 0 else np.zeros(3)
    return np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis])


def angle_deg(a, b):  # the angle between two attitudes
    return 2 * np.degrees(np.arccos(min(1.0, abs(float(a @ b)))))


def derivative(q, w, torque):  # q_NB (B -> N) and w = omega_BN_B [rad/s] of the rigid body
    return 0.5 * qmul(q, np.concatenate([[0.0], w])), (torque - np.cross(w, INERTIA * w)) / INERTIA


def propagate(q, w, torque, dt):  # classic RK4, the quaternion renormalized
    k1 = derivative(q, w, torque)
    k2 = derivative(q + dt / 2 * k1[0], w + dt / 2 * k1[1], torque)
    k3 = derivative(q + dt / 2 * k2[0], w + dt / 2 * k2[1], torque)
    k4 = derivative(q + dt * k3[0], w + dt * k3[1], torque)
    q = q + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
    return q / np.linalg.norm(q), w + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])


def control(q_est, omega_dps, q_target):
    """PD on the estimated error of the target frame R: theta = 2 vec(q_RB), w >= 0; reaction torque [N m]."""
    q_err = qmul(np.array([q_target[0], *-q_target[1:]]), q_est)
    theta = 2 * np.sign(q_err[0] or 1.0) * q_err[1:]
    torque = -INERTIA * (WN**2 * theta + 2 * ZETA * WN * omega_dps * DEG)
    return np.clip(torque, -MAX_TORQUE, MAX_TORQUE)


def gyro_raw(cal, w, t, rng):
    """Raw outputs [V]: the seed unit's scale factors, biases and axes, white noise at its angle random walk."""
    rate_dps = cal.axes_B @ (w / DEG) + rng.normal(0.0, 3e-5 * np.sqrt(RATE_HZ), 4)
    rate_dps[1] += 0.01 if t >= 60.0 else 0.0  # gyro 2's bias step
    return cal.bias_V + cal.scale_factor_V_per_dps * rate_dps


def closed_loop(estimate, cal, seconds, seed):
    """The loop: gyros and tracker sampled, tetra's estimate, control, dynamics; the pointing per epoch."""
    rng = np.random.default_rng(seed)
    q, w = np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3)
    q_target = qexp(np.array([3.0, -2.0, 3.0]) * DEG)  # about 4.7 deg away
    rows = []
    for k in range(int(seconds * RATE_HZ)):
        t = k / RATE_HZ
        tracker = qmul(q, qexp(rng.normal(0.0, 5 / 3600 * DEG, 3))) if k % REFERENCE_EVERY == 0 else None
        q_est, omega_dps, mode = estimate(t, gyro_raw(cal, w, t, rng), tracker)
        torque = control(q_est, omega_dps, q_target)
        for _ in range(SUBSTEPS):
            q, w = propagate(q, w, torque, 1.0 / (RATE_HZ * SUBSTEPS))
        rows.append((t, angle_deg(q, q_target), angle_deg(q, q_est), mode))
    return rows


def over_dds(unit, domain, gyros):
    lock = tetra.dds.Lockstep(unit, gyros=gyros, rate_hz=RATE_HZ, domain=domain)

    def estimate(t, raw, tracker):
        a = lock.step(t, raw, None, tracker, timeout_s=5.0)
        return a.q_RB_wxyz, a.omega_BR_B_rad_s * (180 / np.pi), a.mode  # deg/s as tetra.Pipeline gives it
    return estimate


def in_process(cal):
    pipeline = tetra.Pipeline(cal)

    def estimate(t, raw, tracker):
        a = pipeline.step(t, raw, reference_wxyz=tracker)["attitude"]
        return a["q_RB_wxyz"], a["omega_BR_B_dps"], a["mode"]
    return estimate


def summary(rows):
    pointing = np.array([r[1] for r in rows])
    settled = pointing[int(40 * RATE_HZ):]  # after the slew (4 time constants of 1 / (zeta wn))
    return {"epochs": len(rows), "pointing_final_deg": pointing[-1], "pointing_max_after_40s_deg": settled.max(),
            "knowledge_rms_deg": float(np.sqrt(np.mean([r[2] ** 2 for r in rows]))),
            "modes": sorted({r[3] for r in rows})}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--unit", default="tetra-1")
    ap.add_argument("--domain", type=int, default=None)
    ap.add_argument("--seconds", type=float, default=120.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--compare", action="store_true", help="also run in process and compare the pointing")
    ap.add_argument("--json", help="write the figures to this file")
    args = ap.parse_args()
    cal = tetra.Calibration.read(os.path.join(os.path.dirname(__file__), "..", "seed_unit.yaml"))
    dds_rows = closed_loop(over_dds(args.unit, args.domain, cal.gyro_count), cal, args.seconds, args.seed)
    figures = {"dds": summary(dds_rows)}
    if args.compare:
        local_rows = closed_loop(in_process(cal), cal, args.seconds, args.seed)
        figures["in_process"] = summary(local_rows)
        diff = [abs(a[1] - b[1]) for a, b in zip(dds_rows, local_rows)]
        figures["pointing_difference_max_deg"] = max(diff)
        figures["identical"] = dds_rows == local_rows
    print(json.dumps(figures, indent=1))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(figures, f)
    return 0 if figures.get("identical", True) else 1


if __name__ == "__main__":
    raise SystemExit(main())
