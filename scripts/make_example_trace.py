#!/usr/bin/python3
"""Writes resources/traces/calm-sigh.csv, the synthetic example volume trace (docs/patterns.md).

Not a measurement: calm breathing (15 b/m, 0.5 L tidal: 1.6 s raised-cosine inspiration, 2.4 s
raised-cosine expiration) above a 2.4 L end-expiratory volume, one sigh (1.0 L in 2.4 s, out in 3.6 s)
after the third breath, sampled at 50 Hz with 5 mL of Gaussian noise (seed 19) standing in for a
spirometer's. Deterministic: running it again writes the same file.

Usage: scripts/make_example_trace.py [OUT]
"""
import sys

import numpy as np

RATE = 50.0  # [Hz]
REST = 2.4  # [L] end-expiratory volume
# (inspiration [s], expiration [s], tidal volume [L]) per breath
BREATHS = [(1.6, 2.4, 0.5)] * 3 + [(2.4, 3.6, 1.0)] + [(1.6, 2.4, 0.5)] * 3


def curve():
    t, v, start = [], [], 0.0
    for ti, te, vt in BREATHS:
        for k in range(int(round((ti + te) * RATE))):
            s = k / RATE
            rise = 0.5 * (1 - np.cos(np.pi * s / ti)) if s < ti else 0.5 * (1 + np.cos(np.pi * (s - ti) / te))
            t.append(start + s)
            v.append(REST + vt * rise)
        start += ti + te
    t.append(start)
    v.append(REST)
    return np.array(t), np.array(v)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "resources/traces/calm-sigh.csv"
    t, v = curve()
    v = v + np.random.default_rng(19).normal(0.0, 0.005, v.size)
    with open(out, "w") as f:
        f.write("# synthetic example trace, written by scripts/make_example_trace.py (not a measurement)\n")
        f.write("time [s],volume [L]\n")
        for a, b in zip(t, v):
            f.write(f"{a:.3f},{b:.4f}\n")


if __name__ == "__main__":
    main()
