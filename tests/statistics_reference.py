#!/usr/bin/env python3
"""Reference values for tests/test_statistics.cpp, computed independently of the C++ code: no incomplete
beta or gamma function, only the defining sums (binomial and Poisson CDFs) in 60-digit decimal arithmetic,
solved for the parameter by bisection. Run: python3 tests/statistics_reference.py"""
from decimal import Decimal, getcontext
from fractions import Fraction
from math import comb

getcontext().prec = 60


def binom_cdf(k, n, p):  # P(X <= k), X ~ Binomial(n, p)
    p = Decimal(p)
    return sum(Decimal(comb(n, j)) * p ** j * (1 - p) ** (n - j) for j in range(k + 1))


def poisson_cdf(k, lam):  # P(X <= k), X ~ Poisson(lam)
    lam = Decimal(lam)
    term, total = Decimal(1), Decimal(1)
    for j in range(1, k + 1):
        term = term * lam / j
        total += term
    return total * (-lam).exp()


def solve(f, target, lo, hi, decreasing):
    lo, hi = Decimal(lo), Decimal(hi)
    for _ in range(200):
        mid = (lo + hi) / 2
        above = f(mid) > target
        if above == decreasing:
            lo = mid
        else:
            hi = mid
    return (lo + hi) / 2


def cp(k, n, conf):
    a = Decimal(1 - conf) / 2
    # P(X >= k) increases with p: the lower bound is where it equals a.
    lower = Decimal(0) if k == 0 else solve(lambda p: 1 - binom_cdf(k - 1, n, p), a, 0, 1, False)
    upper = Decimal(1) if k == n else solve(lambda p: binom_cdf(k, n, p), a, 0, 1, True)
    return lower, upper


def garwood(k, conf):
    a = Decimal(1 - conf) / 2
    lower = Decimal(0) if k == 0 else solve(lambda l: 1 - poisson_cdf(k - 1, l), a, 0, 10 * k + 50, False)
    upper = solve(lambda l: poisson_cdf(k, l), a, 0, 10 * k + 50, True)
    return lower, upper


def reg_beta_int(x, a, b):  # I_x(a, b) for whole a, b: P(Binomial(a + b - 1, x) >= a), exactly
    x = Fraction(x)
    n = a + b - 1
    return float(sum(comb(n, j) * x ** j * (1 - x) ** (n - j) for j in range(a, n + 1)))


if __name__ == "__main__":
    for k, n in [(0, 10), (3, 10), (10, 10), (5, 100), (0, 1000), (17, 520), (1, 3000)]:
        lo, up = cp(k, n, 0.95)
        print(f"CP95 k={k} n={n}: {float(lo):.17g} {float(up):.17g}")
    for k, n in [(0, 2995), (2, 520)]:
        up = solve(lambda p: binom_cdf(k, n, p), Decimal("0.05"), 0, 1, True)
        print(f"CP95 one-sided upper k={k} n={n}: {float(up):.17g}")
    for k in [0, 1, 2, 10, 50]:
        lo, up = garwood(k, 0.95)
        print(f"Garwood95 k={k}: {float(lo):.17g} {float(up):.17g}")
    for x, a, b in [("0.3", 2, 5), ("0.9", 7, 3), ("1/1000", 1, 2995), ("0.02", 18, 503)]:
        print(f"I_{x}({a},{b}) = {reg_beta_int(Fraction(x), a, b):.17g}")
