"""How far knowing the room's light could take the shipped tracker (issue 52): an upper bound.

For each detectable single walker, the shipped tracker's longest track is remapped by a straight
line x_true = a + b * x_track fitted on the other walkers lit the same way (leave one clip out,
the recordings' `lighting` column as if a run-time command knew it). No run-time command knows the
light (README.md: three cues failed), so these figures bound any light-aware correction of where
the streak is. The remapped figures are paired with the shipped ones (McNemar).

    python research/track/oracle.py
"""
from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "recordings"))
from common import TRANSFER, mcnemar  # noqa: E402
from data import clips  # noqa: E402
from wallcli.signal.track import track_rows  # noqa: E402
from wallcli.train.recordings import FPS  # noqa: E402


def figures(xe, xt):
    r = float(np.corrcoef(xe, xt)[0, 1]) if len(xe) > 2 and np.std(xe) > 0 and np.std(xt) > 0 else 0.0
    return r, float(np.median(np.abs(xe - xt)))


def main():
    light = {r["file"]: r["lighting"] for r in csv.DictReader(open(TRANSFER / "labels.csv"))}
    W = {}
    for c in clips():
        if not (c.people == 1 and c.activity == "walking" and c.detectable):
            continue
        tracks = track_rows(c.h, np.arange(c.h.shape[0]) / FPS, FPS)
        if not tracks:
            W[c.name] = None
            continue
        tr = max(tracks, key=lambda t: t.duration)
        t = np.asarray(tr.t)
        W[c.name] = (np.asarray(tr.x), np.interp(t, np.arange(c.x.shape[1]) / FPS, c.x[0]))
    names = sorted(W)
    base, remap = {}, {}
    for n in names:
        if W[n] is None:
            base[n] = remap[n] = (0.0, 1.0)
            continue
        base[n] = figures(*W[n])
        same = [m for m in names if m != n and W[m] is not None and light[m] == light[n]]
        xe = np.concatenate([W[m][0] for m in same])
        xt = np.concatenate([W[m][1] for m in same])
        b, a = np.polyfit(xe, xt, 1)
        remap[n] = figures(a + b * W[n][0], W[n][1])
    for label, f in (("r >= 0.8", lambda v: v[0] >= 0.8), ("median error <= 0.25", lambda v: v[1] <= 0.25)):
        s = np.array([f(base[n]) for n in names])
        o = np.array([f(remap[n]) for n in names])
        g, l, p = mcnemar(s, o)
        print(f"{label:22s} shipped {s.sum():2d}/{len(names)}   light known, line refit {o.sum():2d}/{len(names)} "
              f"(+{g} -{l}, p = {p:.2f})")
    for lt in sorted(set(light[n] for n in names)):
        sel = [n for n in names if light[n] == lt]
        print(f"  {lt:15s} {len(sel)} walkers: r>=0.8 {sum(base[n][0] >= 0.8 for n in sel)} -> "
              f"{sum(remap[n][0] >= 0.8 for n in sel)}, error<=0.25 {sum(base[n][1] <= 0.25 for n in sel)} -> "
              f"{sum(remap[n][1] <= 0.25 for n in sel)}")


if __name__ == "__main__":
    main()
