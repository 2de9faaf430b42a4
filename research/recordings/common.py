"""Shared pieces of the out-of-fold studies on the recordings (../shared/transfer)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from wallcli.train.recordings import fold_of, load_recordings

ROOT = Path(__file__).resolve().parents[2]
TRANSFER = ROOT.parent / "shared" / "transfer"
CACHE = ROOT / "runs" / "reccache"
K = 5
COUNT_CLASSES = [0, 1, 2]
ACT_CLASSES = ["none", "walking", "crouching", "waving", "jumping"]


def recordings():
    return load_recordings([TRANSFER], CACHE)


def band(r) -> str:
    if r.people == 0:
        return "empty"
    if r.snr_db is None or r.snr_db < 0:
        return "<0"
    return "0-10" if r.snr_db < 10 else ">=10"


def truth(r, task):
    return r.people if task == "count" else r.activity


def scored(r, task) -> bool:
    """Clips scored for a task (activity: at most one person)."""
    return task == "count" or r.persons <= 1


def mcnemar(a: np.ndarray, b: np.ndarray) -> tuple[int, int, float]:
    """(b right where a wrong, a right where b wrong, exact two-sided p)."""
    a, b = np.asarray(a, bool), np.asarray(b, bool)
    gain, loss = int((b & ~a).sum()), int((a & ~b).sum())
    n = gain + loss
    if n == 0:
        return gain, loss, 1.0
    k = min(gain, loss)
    p = sum(math.comb(n, i) for i in range(k + 1)) / 2 ** n * 2
    return gain, loss, min(1.0, p)


def table(recs, right, task, decided=None) -> str:
    rows = []
    for b in ("empty", "<0", "0-10", ">=10"):
        sel = [i for i, r in enumerate(recs) if band(r) == b and scored(r, task)]
        d = ""
        if decided is not None:
            dd = [i for i in sel if decided[i]]
            d = f" dec {len(dd)} ({sum(right[i] for i in dd)})"
        rows.append(f"{b}: {sum(right[i] for i in sel)}/{len(sel)}{d}")
    det = [i for i, r in enumerate(recs) if scored(r, task) and r.detectable]
    rows.append(f"det: {sum(right[i] for i in det)}/{len(det)} = {np.mean([right[i] for i in det]):.3f}")
    return " | ".join(rows)
