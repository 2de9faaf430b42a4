"""The tracker's smoothing and speed limit chosen out of fold on the recordings' single walkers.

For each fold: every setting of the grid scored on the other folds' detectable single walkers (clips
whose longest track reaches r >= 0.8 with the truth, then clips with median error <= 0.25), the best
applied to the fold. Prints each fold's choice and the out-of-fold figures, beside the shipped
setting's.

    python research/track/tune.py
"""
from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from data import clips  # noqa: E402
from evaluate import walker_figures  # noqa: E402
import wallcli.signal.track as tr  # noqa: E402
from wallcli.train.recordings import FPS  # noqa: E402

GRID = {"SMOOTH_SECONDS": [0.1, 0.3], "SMOOTH_BINS": [1.5, 3.0], "MAX_SPEED": [0.5, 1.0, 2.0],
        "RELATIVE": [0.35, 0.6]}


def score(cs, setting):
    for k, v in setting.items():
        setattr(tr, k, v)
    out = []
    for c in cs:
        T = c.h.shape[0]
        f = walker_figures(c, tr.track_rows(c.h, np.arange(T) / FPS, FPS))
        out.append((f["r"] >= 0.8, f["err"] <= 0.25) if f else (False, False))
    return np.array(out, bool)


def main() -> None:
    W = [c for c in clips() if c.people == 1 and c.activity == "walking" and c.detectable]
    shipped = {k: getattr(tr, k) for k in GRID}
    settings = [dict(zip(GRID, v)) for v in itertools.product(*GRID.values())]
    res = {i: score(W, s) for i, s in enumerate(settings)}
    folds = np.array([c.fold for c in W])
    oof = np.zeros((len(W), 2), bool)
    for k in range(5):
        tr_ = folds != k
        best = max(res, key=lambda i: (res[i][tr_, 0].sum(), res[i][tr_, 1].sum()))
        oof[folds == k] = res[best][folds == k]
        print(f"fold {k}: {settings[best]}")
    base = score(W, shipped)
    print(f"shipped {shipped}: r>=0.8 {base[:, 0].sum()}/{len(W)}, err<=0.25 {base[:, 1].sum()}/{len(W)}")
    print(f"out of fold: r>=0.8 {oof[:, 0].sum()}/{len(W)}, err<=0.25 {oof[:, 1].sum()}/{len(W)}")
    best_all = max(res, key=lambda i: (res[i][:, 0].sum(), res[i][:, 1].sum()))
    print(f"in sample best {settings[best_all]}: {res[best_all][:, 0].sum()}, {res[best_all][:, 1].sum()}")


if __name__ == "__main__":
    main()
