"""Figures from per-clip rows: accuracy with its interval, confusion, decided answers, and
accuracy per class, per measured-SNR band and per confidence bin (reliability).

Clips are the unit: the headline interval is a bootstrap over clips (percentile, 10 000
resamples, a fixed seed, so the same rows always give the same interval). Sub-groups (a class, an
SNR band) hold a handful of clips each, where a bootstrap of 3 right out of 3 would say [1, 1];
they get Wilson score intervals, which stay honest at small counts. A row with an error counts as
a wrong answer and as undecided; it has no place in the confusion matrix (its truth is counted
under ``errors_by_class``).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

BOOTSTRAP = 10_000
SEED = 0
Z95 = 1.959963984540054
# measured SNR bands (dB): edges between them
SNR_EDGES = (-5.0, 0.0, 5.0, 10.0)
# CONTRACT.md's by_band: (name, [lo, hi) in dB). Under 0 dB a person is hard to tell from an empty
# room; from 10 dB up plain to see in a space-time plot (the transfer set's README).
BANDS = (("empty", None, None), ("<0 dB", None, 0), ("0-10 dB", 0, 10), (">=10 dB", 10, None))
UNMEASURED = "not measured"
CONFIDENCE_BINS = 10


def correct(row: dict) -> bool:
    return row.get("error") is None and row.get("label") == row.get("truth")


def decided(row: dict) -> bool:
    return row.get("error") is None and row.get("confident") is True


def bootstrap_ci(hits: np.ndarray, *, n: int = BOOTSTRAP, seed: int = SEED) -> list[float] | None:
    """95 % percentile interval of the mean of 0/1 ``hits``, resampling clips.

    A resample of N clips with replacement holds Binomial(N, k/N) right answers (k right in
    ``hits``): drawn as that, the same distribution costs memory of the resamples only, not of
    resamples x clips (10 000 x 100 000 clips was 8 GB)."""
    hits = np.asarray(hits, np.float64)
    if hits.size == 0:
        return None
    rng = np.random.default_rng(seed)
    means = rng.binomial(hits.size, float(hits.sum()) / hits.size, n) / hits.size
    lo, hi = np.percentile(means, [2.5, 97.5])
    return [float(lo), float(hi)]


def wilson_ci(k: int, n: int) -> list[float] | None:
    if n == 0:
        return None
    p = k / n
    d = 1 + Z95**2 / n
    c = (p + Z95**2 / (2 * n)) / d
    h = Z95 * math.sqrt(p * (1 - p) / n + Z95**2 / (4 * n * n)) / d
    return [max(0.0, c - h), min(1.0, c + h)]


def _ratio(k: int, n: int) -> float | None:
    return k / n if n else None


def summary(rows: list[dict], classes: list) -> dict[str, Any]:
    """The headline block: scored, accuracy, ci95, decided, coverage, accuracy_decided, confusion."""
    hits = np.array([correct(r) for r in rows], bool)
    dec = [r for r in rows if decided(r)]
    k = len(classes)
    confusion = [[0] * k for _ in range(k)]
    errors_by_class = [0] * k
    pos = {c: i for i, c in enumerate(classes)}
    for r in rows:
        i = pos[r["truth"]]
        if r.get("error") is not None:
            errors_by_class[i] += 1
        else:
            confusion[i][pos[r["label"]]] += 1
    right_decided = sum(correct(r) for r in dec)
    return {
        "scored": len(rows),
        "errors": sum(r.get("error") is not None for r in rows),
        "correct": int(hits.sum()),
        "accuracy": _ratio(int(hits.sum()), len(rows)),
        "ci95": bootstrap_ci(hits),
        "decided": len(dec),
        "coverage": _ratio(len(dec), len(rows)),
        "accuracy_decided": _ratio(right_decided, len(dec)),
        "correct_decided": right_decided,
        "ci95_decided": wilson_ci(right_decided, len(dec)),
        "confusion": confusion,
        "errors_by_class": errors_by_class,
    }


def _group(rows: list[dict]) -> dict[str, Any]:
    k = sum(correct(r) for r in rows)
    dec = [r for r in rows if decided(r)]
    kd = sum(correct(r) for r in dec)
    return {"clips": len(rows), "correct": k, "accuracy": _ratio(k, len(rows)), "ci95": wilson_ci(k, len(rows)),
            "decided": len(dec), "accuracy_decided": _ratio(kd, len(dec))}


def per_class(rows: list[dict], classes: list) -> list[dict]:
    return [{"class": c, **_group([r for r in rows if r["truth"] == c])} for c in classes]


def by_snr(rows: list[dict], edges=SNR_EDGES) -> list[dict]:
    """Accuracy per band of measured SNR; rows without a measurement (errors, plots) last."""
    bounds = [-math.inf, *edges, math.inf]
    out = []
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        sel = [r for r in rows if r.get("snr_db") is not None and lo <= r["snr_db"] < hi]
        if sel:
            out.append({"snr_db": [None if math.isinf(lo) else lo, None if math.isinf(hi) else hi], **_group(sel)})
    rest = [r for r in rows if r.get("snr_db") is None]
    if rest:
        out.append({"snr_db": None, **_group(rest)})
    return out


def band_of(empty: bool, snr_db: float | None) -> str:
    """The by_band name of a clip: empty rooms by their truth, the others by SNR."""
    if empty:
        return "empty"
    if snr_db is None:
        return UNMEASURED
    return next(name for name, lo, hi in BANDS[1:] if (lo is None or snr_db >= lo) and (hi is None or snr_db < hi))


def by_band(rows: list[dict]) -> list[dict]:
    """Clips, right, decided and decided-and-right per band of ``row['band']``: always the four
    bands, then one for clips whose SNR is unknown (failed or a plot file, measured SNR) if any."""
    out = []
    for name, lo, hi in (*BANDS, (UNMEASURED, None, None)):
        sel = [r for r in rows if r["band"] == name]
        if name == UNMEASURED and not sel:
            continue
        dec = [r for r in sel if decided(r)]
        out.append({"snr_db": None if name == UNMEASURED else [lo, hi], "band": name, "clips": len(sel),
                    "correct": sum(map(correct, sel)), "decided": len(dec), "correct_decided": sum(map(correct, dec))})
    return out


def reliability(rows: list[dict], bins: int = CONFIDENCE_BINS) -> dict[str, Any]:
    """Confidence (the clip answer's probability) against how often such answers are right.

    ``ece`` is the expected calibration error: the clip-weighted mean gap between a bin's mean
    confidence and its accuracy (0 = a probability of 0.8 is right 80 % of the time).
    """
    answered = [r for r in rows if r.get("error") is None and r.get("probabilities")]
    conf = np.array([max(r["probabilities"]) for r in answered], np.float64)
    hit = np.array([correct(r) for r in answered], np.float64)
    out, gap = [], 0.0
    for b in range(bins):
        lo, hi = b / bins, (b + 1) / bins
        sel = (conf >= lo) & ((conf < hi) if b < bins - 1 else (conf <= hi))
        n = int(sel.sum())
        if n:
            mc, acc = float(conf[sel].mean()), float(hit[sel].mean())
            gap += n * abs(mc - acc)
            out.append({"confidence": [lo, hi], "clips": n, "mean_confidence": mc, "accuracy": acc})
    return {"bins": out, "ece": gap / len(answered) if answered else None}
