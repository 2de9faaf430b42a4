"""Probe: the plots' temporal noise spectrum, per window, against the consecutive-difference estimate.

For each clip, count runs in-process; every window handed to window_signal_db is also measured by
an AR(1) fit of its high-frequency spectrum (white-equivalent noise level at low frequencies).

    python research/noise/psd_probe.py OUT.jsonl CLIP...
"""
from __future__ import annotations

import json
import sys

import numpy as np
from windows import clip_windows

A_GRID = np.linspace(0.0, 0.95, 96)


def spectrum(ys: list[np.ndarray]) -> np.ndarray:
    """(n, F) mean periodogram (per-sample variance density) of windows ys[i] (n, bins, T, 3)."""
    acc = 0.0
    for y in ys:
        T = y.shape[-2]
        w = np.hanning(T)
        Y = np.fft.rfft(y * w[:, None], axis=-2)
        acc = acc + np.mean(np.abs(Y) ** 2, axis=(-3, -1)) / np.sum(w * w)
    return acc / len(ys)


def ar1_fit(P: np.ndarray, T: int, fps: float, lo: float, hi: float):
    k = np.arange(P.shape[-1])
    f = k * fps / T
    sel = (f >= lo) & (f <= hi)
    om = 2 * np.pi * k[sel] / T
    lp = np.log(np.maximum(P[..., sel], 1e-300))
    den = 1 + A_GRID[:, None] ** 2 - 2 * A_GRID[:, None] * np.cos(om)[None]  # (A, F)
    ld = np.log(den)
    logc = np.mean(lp[..., None, :] + ld, axis=-1)  # (n, A)
    res = np.sum((lp[..., None, :] + ld - logc[..., None]) ** 2, axis=-1)
    j = np.argmin(res, axis=-1)
    a = A_GRID[j]
    c = np.exp(np.take_along_axis(logc, j[..., None], -1)[..., 0])
    return a, c


def main() -> None:
    with open(sys.argv[1], "a") as fh:
        for clip in sys.argv[2:]:
            got = clip_windows(clip)
            if got is None:
                continue
            dbs, ys = got
            T = ys[0].shape[-2]
            P = spectrum(ys)
            total = sum(np.mean(y ** 2, axis=(-3, -2, -1)) for y in ys) / len(ys)
            diffn = sum(0.5 * np.mean(np.diff(y, axis=-2) ** 2, axis=(-3, -2, -1)) for y in ys) / len(ys)
            rec = {"clip": clip, "db_old": dbs.tolist(), "total": total.tolist(), "diffnoise": diffn.tolist()}
            for name, lo, hi in (("a3_12", 3, 12), ("a4_15", 4, 15), ("a2_12", 2, 12)):
                a, c = ar1_fit(P, T, 30.0, lo, hi)
                nvar = c / (1 - a * a)
                neq = c / (1 - a) ** 2
                sig = total - nvar
                db = np.maximum(10 * np.log10(np.maximum(sig / neq, 1e-30)), -30)
                rec[name] = {"a": a.tolist(), "db": db.tolist()}
            # spectrum shape summary: mean P in 1-Hz bands
            f = np.arange(P.shape[-1]) * 30.0 / T
            rec["bands"] = [float(np.mean(P[:, (f >= b) & (f < b + 1.5)])) for b in np.arange(0, 15, 1.5)]
            fh.write(json.dumps(rec) + "\n")
            fh.flush()
            print(clip, np.round(np.mean(dbs), 2), "a", np.round(np.mean(rec["a3_12"]["a"]), 2),
                  "new", np.round(np.mean(rec["a3_12"]["db"]), 2), file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
