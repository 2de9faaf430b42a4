"""Probe: how the plots' differences grow with the lag, and how heavy their tails are, per clip.

N(k) = half the mean square of y(t + k) - y(t) (the light changes removed): white noise keeps N(k)
flat, a smooth signal grows as k^2, a codec's held noise (blocks that step now and then) grows as k
until its hold is over. Kurtosis of the lag-1 differences: 3 for Gaussian noise, far more for steps.

    python research/noise/lag_probe.py CLIP...
"""
from __future__ import annotations

import sys

import numpy as np
from windows import clip_windows

LAGS = (1, 2, 4, 8, 16)


def main() -> None:
    print("clip | signal_db | N(k)/N(1), k = " + ", ".join(map(str, LAGS[1:])) + " | kurtosis(dy) | zero share")
    for clip in sys.argv[1:]:
        got = clip_windows(clip)
        if got is None:
            print(clip, "no windows")
            continue
        dbs, ys = got
        n = {k: sum(0.5 * np.mean((y[..., k:, :] - y[..., :-k, :]) ** 2) for y in ys) for k in LAGS}
        d = np.concatenate([np.diff(y, axis=-2).ravel() for y in ys])
        kurt = float(np.mean(d ** 4) / np.mean(d ** 2) ** 2)
        zero = float(np.mean(np.abs(d) < 1e-6 * np.sqrt(np.mean(d ** 2))))
        print(f"{clip.split('/')[-1]} | {np.mean(dbs):.2f} | " + ", ".join(f"{n[k] / n[1]:.2f}" for k in LAGS[1:])
              + f" | {kurt:.1f} | {zero:.3f}", flush=True)


if __name__ == "__main__":
    main()
