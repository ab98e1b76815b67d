#!/usr/bin/env python3
"""The healthy gyro's tail of the three-gyro own noise level (docs/fdi.md, "Three gyros: a gyro's own noise
level"; fdi/src/own_noise_level.hpp): white noise, its fourth differences, the median of |Δ⁴| over a window
of 30 (noise_window) evaluated every 10 values, over the white-noise median 0.6745·√70. Prints how often the
level exceeds 2, 2.5, 3 (and the window of 60 for comparison), and the lag-1 correlation of Δ⁴.

Usage: /usr/bin/python3 bench/own_noise_tail.py [SAMPLES] [SEED]   (defaults 20,000,000 and 1; numpy; about
20 s and 3 GB for the default)
"""
import sys

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

MEDIAN_HALF_NORMAL = 0.6744897501960817


def main() -> int:
    samples = int(sys.argv[1]) if len(sys.argv) > 1 else 20_000_000
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    x = np.random.default_rng(seed).standard_normal(samples)
    d4 = x[4:] - 4 * x[3:-1] + 6 * x[2:-2] - 4 * x[1:-3] + x[:-4]
    print(f"lag-1 correlation of the fourth difference: {np.corrcoef(d4[1:], d4[:-1])[0, 1]:.3f} (theory -0.8)")
    level = np.abs(d4) / np.sqrt(70.0)
    for window in (30, 60):
        r = np.median(sliding_window_view(level, window)[::10], axis=1) / MEDIAN_HALF_NORMAL
        tails = ", ".join(f"P(r > {t:g}) = {(r > t).mean():.2g}" for t in (2.0, 2.5, 3.0))
        print(f"window {window}: {len(r)} evaluations, median r {np.median(r):.3f}, max {r.max():.2f}; {tails}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
