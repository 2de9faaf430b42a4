"""Probe: is the plots' noise temporally coloured? Read on the noise alone: the spatially fine part
of each window (DCT across the bins, components >= KCUT: a hidden person's light on a wall is
spatially smooth), its temporal spectrum at the signal's frequencies against its high frequencies.

    python research/noise/colour_probe.py OUT.jsonl CLIP...
"""
from __future__ import annotations

import json
import sys

import numpy as np
from windows import clip_windows

from wallcli.signal.window import _dct_rows

LOW = (0.3, 2.5)
HIGH = (6.0, 12.0)


def probe(ys, fps=30.0, kcuts=(8, 16, 32)):
    out = {}
    for kc in kcuts:
        L = H = Hy = 0.0
        for y in ys:  # (n, bins, T, 3)
            n_b, T = y.shape[-3], y.shape[-2]
            B = _dct_rows(n_b)[kc:]  # fine components
            z = np.einsum("kb,nbtc->nktc", B, y)
            w = np.hanning(T)
            f = np.fft.rfftfreq(T, 1 / fps)
            Pz = np.mean(np.abs(np.fft.rfft(z * w[:, None], axis=-2)) ** 2, axis=(-3, -1)) / np.sum(w * w)
            Py = np.mean(np.abs(np.fft.rfft(y * w[:, None], axis=-2)) ** 2, axis=(-3, -1)) / np.sum(w * w)
            lo = (f >= LOW[0]) & (f <= LOW[1])
            hi = (f >= HIGH[0]) & (f <= HIGH[1])
            L = L + Pz[:, lo].mean(-1)
            H = H + Pz[:, hi].mean(-1)
            Hy = Hy + Py[:, hi].mean(-1)
        out[kc] = {"R": (L / H).tolist(), "Hy": Hy.tolist(), "Hz": H.tolist()}
    return out


def main() -> None:
    with open(sys.argv[1], "a") as fh:
        for clip in sys.argv[2:]:
            got = clip_windows(clip)
            if got is None:
                continue
            dbs, ys = got
            total = sum(np.mean(y ** 2, axis=(-3, -2, -1)) for y in ys)
            diffn = sum(0.5 * np.mean(np.diff(y, axis=-2) ** 2, axis=(-3, -2, -1)) for y in ys)
            rec = {"clip": clip, "db_old": dbs.tolist(), "total": total.tolist(), "diffnoise": diffn.tolist(),
                   "probe": probe(ys)}
            fh.write(json.dumps(rec) + "\n")
            fh.flush()
            print(clip.split("/")[-1], np.round(np.mean(dbs), 2), "R",
                  [round(float(np.median(rec["probe"][k]["R"])), 2) for k in rec["probe"]], file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
