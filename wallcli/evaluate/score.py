"""Figures from per-clip rows: accuracy with its interval, confusion, decided answers, and
accuracy per class, per measured-SNR band and per confidence bin (reliability).

Clips are the unit. Every interval is the exact binomial one (Clopper-Pearson, 95 %): a
bootstrap of 6 right out of 6 resamples only right answers and said [1, 1] ("100-100 %"), and a
set of a few clips is what a user scores first; the exact interval says 54-100 % there, and
never claims less than the count shows. A row with an error counts as a wrong answer and as
undecided; it has no place in the confusion matrix (its truth is counted under
``errors_by_class``).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

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


def _binom_cdf(k: int, n: int, p: float, logc: np.ndarray) -> float:
    """P(X <= k) for X ~ Binomial(n, p); ``logc``: log C(n, i) for i = 0..n."""
    i = np.arange(k + 1)
    terms = logc[: k + 1] + i * math.log(p) + (n - i) * math.log1p(-p)
    top = terms.max()
    return float(min(1.0, math.exp(top) * np.exp(terms - top).sum()))


def _solve(f, target: float) -> float:
    """The p in (0, 1) where the decreasing f(p) crosses target, by bisection (to 1e-12)."""
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if f(mid) > target else (lo, mid)
    return (lo + hi) / 2


def exact_ci(k: int, n: int, level: float = 0.95) -> list[float] | None:
    """Clopper-Pearson interval of k right out of n: the p at which k or more (k or fewer) right
    would be as rare as (1 - level) / 2. numpy and the stdlib only (scipy is no runtime need):
    the binomial CDF, summed in logs, solved by bisection; 100 000 clips take a few ms."""
    k, n = int(k), int(n)
    if n <= 0:
        return None
    a = (1 - level) / 2
    logfact = np.concatenate([[0.0], np.cumsum(np.log(np.arange(1, n + 1)))])
    logc = logfact[n] - logfact - logfact[::-1]
    # lower: P(X >= k | p) = a, i.e. P(X <= k - 1 | p) = 1 - a; upper: P(X <= k | p) = a
    lo = 0.0 if k == 0 else _solve(lambda p: _binom_cdf(k - 1, n, p, logc), 1 - a)
    hi = 1.0 if k == n else _solve(lambda p: _binom_cdf(k, n, p, logc), a)
    return [lo, hi]


def exact_ci_of(hits) -> list[float] | None:
    """:func:`exact_ci` of 0/1 ``hits``."""
    hits = np.asarray(hits, bool)
    return exact_ci(int(hits.sum()), hits.size)


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
        "ci95": exact_ci_of(hits),
        "decided": len(dec),
        "coverage": _ratio(len(dec), len(rows)),
        "accuracy_decided": _ratio(right_decided, len(dec)),
        "correct_decided": right_decided,
        "ci95_decided": exact_ci(right_decided, len(dec)),
        "confusion": confusion,
        "errors_by_class": errors_by_class,
    }


def _group(rows: list[dict]) -> dict[str, Any]:
    k = sum(correct(r) for r in rows)
    dec = [r for r in rows if decided(r)]
    kd = sum(correct(r) for r in dec)
    return {"clips": len(rows), "correct": k, "accuracy": _ratio(k, len(rows)), "ci95": exact_ci(k, len(rows)),
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
