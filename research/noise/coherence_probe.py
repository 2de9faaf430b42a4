"""Probe: is a plot's slow change spatially coherent (a person's light on the wall moves many bins
together) or spatially white (a codec's held residue, bin by bin)? The power at 0.1-2.5 Hz in each
spatial DCT component across the bins: coarse (1..7) against fine (16..) components, per component.

    python research/noise/coherence_probe.py CLIP...
"""
from __future__ import annotations

import sys

import numpy as np
from windows import clip_windows

from wallcli.signal.window import _dct_rows

LOW = (0.1, 2.5)


def coherence(ys, fps: float = 30.0) -> tuple[np.ndarray, np.ndarray]:
    """Per window: (coarse / fine slow power per component, fine slow / fine fast power)."""
    co = fi = fh = 0.0
    for y in ys:  # (n, bins, T, 3)
        n_b, T = y.shape[-3], y.shape[-2]
        z = np.einsum("kb,nbtc->nktc", _dct_rows(n_b), y)
        w = np.hanning(T)
        P = np.abs(np.fft.rfft(z * w[:, None], axis=-2)) ** 2 / np.sum(w * w)  # (n, k, F, 3)
        f = np.fft.rfftfreq(T, 1 / fps)
        lo = (f >= LOW[0]) & (f <= LOW[1])
        hi = f >= 6.0
        co = co + P[:, 1:8][:, :, lo].mean(axis=(1, 2, 3))
        fi = fi + P[:, 16:][:, :, lo].mean(axis=(1, 2, 3))
        fh = fh + P[:, 16:][:, :, hi].mean(axis=(1, 2, 3))
    return co / fi, fi / fh


def main() -> None:
    print("clip | signal_db | coarse/fine slow (median over windows) | fine slow/fast")
    for clip in sys.argv[1:]:
        got = clip_windows(clip)
        if got is None:
            print(clip, "no windows")
            continue
        dbs, ys = got
        c, r = coherence(ys)
        print(f"{clip.split('/')[-1]} | {np.mean(dbs):.2f} | {np.median(c):.1f} | {np.median(r):.1f}", flush=True)


if __name__ == "__main__":
    main()
