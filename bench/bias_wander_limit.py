#!/usr/bin/env python3
"""How long the data need to show a bias instability worse than stated (docs/fdi.md, "What the data cannot
tell"; docs/fdi_validation.md, "A bias wander the data cannot show yet").

A unit whose bias instability B is k times its `noise:` figure (its white noise N as stated, or
--white-factor times) shows it only
in the slow part of what it measures: the parity (d = N_gyros - 3 values, the differential biases) or, with
three gyros and a reference, the rates the reference measures (d = 3, the common biases, against the same
white rate noise at low frequency). Over D minutes, the 10-s means x of one such value are Gaussian, with
covariance C_k = N²/10 s · I + (the Gauss–Markov process of σ = 1.076·k·B and T_c, averaged over blocks),
under the truth and C_1 under the model. The Kullback–Leibler divergence KL(C_k || C_1) per value, times d,
is the expected log-likelihood ratio ℓ of the best test there is (Neyman–Pearson, told k in advance). Two
bounds on what a test whose false-alarm probability is at most α can detect over D: at most β with
β·ln(β/α) + (1 − β)·ln((1 − β)/(1 − α)) ≤ d·KL (the data-processing inequality: no test does better), and
at least the share of draws under the truth with ℓ > ln(1/α) (that test's false alarms are at most α by
Markov's inequality: a test that exists, told k). Prints per k, D and d: KL [nats] and the two bounds, at
α = the budget's largest share of false_alarm_probability (1e-6 at the default 1e-9).

Usage: /usr/bin/python3 bench/bias_wander_limit.py [--factors 1.5,2,2.5,3] [--minutes 10,30,60]
       [--alpha 1e-6] [--arw 3e-5] [--white-factor 1] [--instability 5e-6] [--correlation-s 100]   --draws 2000 --seed 1 (numpy; about a minute)
"""
import argparse
import math

import numpy as np

GAUSS_MARKOV_SIGMA_PER_B = 1.0760  # σ of the Gauss–Markov model of B (core/correlated_noise.hpp)
BLOCK_S = 10.0                     # [s] the means the divergence is taken over


def block_covariance(blocks, arw_dps_rts, gm_sigma_dps, correlation_s):
    """[(deg/s)²] covariance of `blocks` consecutive BLOCK_S-means of white rate noise plus a
    first-order Gauss–Markov bias."""
    lag = np.abs(np.arange(blocks)[:, None] - np.arange(blocks)[None, :]) * BLOCK_S
    a = BLOCK_S / correlation_s
    g = gm_sigma_dps**2 / a**2
    gm = np.where(lag == 0, 2.0 * g * (a - 1.0 + math.exp(-a)),
                  g * (np.exp(-(lag - BLOCK_S) / correlation_s) - 2.0 * np.exp(-lag / correlation_s) +
                       np.exp(-(lag + BLOCK_S) / correlation_s)))
    return gm + np.eye(blocks) * arw_dps_rts**2 / BLOCK_S


def divergence(truth, model):
    """KL(N(0, truth) || N(0, model)) [nats]."""
    s = np.linalg.solve(model, truth)
    sign, logdet = np.linalg.slogdet(s)
    return 0.5 * (np.trace(s) - len(s) - logdet)


def largest_power(kl, alpha):
    """The largest β with β·ln(β/α) + (1 − β)·ln((1 − β)/(1 − α)) ≤ kl (bisection; β ≥ α)."""
    def spent(beta):
        tail = (1.0 - beta) * math.log((1.0 - beta) / (1.0 - alpha)) if beta < 1.0 else 0.0
        return beta * math.log(beta / alpha) + tail
    lo, hi = alpha, 1.0
    if spent(hi) <= kl:
        return 1.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if spent(mid) <= kl else (lo, mid)
    return lo


def realized_power(truth, model, dof, alpha, draws, rng):
    """The share of `draws` draws of `dof` values under `truth` whose log-likelihood ratio exceeds
    ln(1/alpha)."""
    lt = np.linalg.cholesky(truth)
    inv_t = np.linalg.inv(truth)
    inv_m = np.linalg.inv(model)
    _, logdet_t = np.linalg.slogdet(truth)
    _, logdet_m = np.linalg.slogdet(model)
    x = lt @ rng.standard_normal((len(truth), draws * dof))
    q = np.einsum("ij,ij->j", x, (inv_m - inv_t) @ x)
    ratio = 0.5 * q.reshape(draws, dof).sum(axis=1) - 0.5 * dof * (logdet_t - logdet_m)
    return float(np.mean(ratio > math.log(1.0 / alpha)))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--factors", default="1.5,2,2.5,3", help="B's true value over the stated (list)")
    p.add_argument("--minutes", default="10,30,60", help="[min] data lengths (list)")
    p.add_argument("--alpha", type=float, default=1e-6, help="the test's false-alarm probability")
    p.add_argument("--arw", type=float, default=3e-5, help="[deg/rt-s] stated white noise N")
    p.add_argument("--instability", type=float, default=5e-6, help="[deg/s] stated bias instability B")
    p.add_argument("--correlation-s", type=float, default=100.0, help="[s] T_c of B's Gauss–Markov model")
    p.add_argument("--white-factor", type=float, default=1.0, help="N's true value over the stated")
    p.add_argument("--draws", type=int, default=2000, help="draws under the truth for the lower bound")
    p.add_argument("--seed", type=int, default=1)
    a = p.parse_args()
    factors = [float(f) for f in a.factors.split(",")]
    minutes = [float(m) for m in a.minutes.split(",")]
    stated = GAUSS_MARKOV_SIGMA_PER_B * a.instability
    print(f"stated N = {a.arw:g} deg/rt-s (true {a.white_factor:g} x), B = {a.instability:g} deg/s, "
          f"T_c = {a.correlation_s:g} s; "
          f"alpha = {a.alpha:g} (ln 1/alpha = {math.log(1.0 / a.alpha):.1f})")
    rng = np.random.default_rng(a.seed)
    print("detection probability within D of a test of false-alarm probability alpha: at least (the likelihood")
    print("ratio test told k, over --draws draws) - at most (any test), for d = 1 / 2 / 3 values")
    print(" B x  minutes  KL per value [nats]    d = 1          d = 2          d = 3")
    for k in factors:
        for m in minutes:
            n = max(2, int(round(m * 60.0 / BLOCK_S)))
            model = block_covariance(n, a.arw, stated, a.correlation_s)
            truth = block_covariance(n, a.white_factor * a.arw, k * stated, a.correlation_s)
            kl = divergence(truth, model)
            bounds = "  ".join(
                f"{realized_power(truth, model, d, a.alpha, a.draws, rng):.2f} - {largest_power(d * kl, a.alpha):.2f}"
                for d in (1, 2, 3))
            print(f"{k:4.2g}  {m:7.0f}  {kl:19.2f}    {bounds}")


if __name__ == "__main__":
    main()
