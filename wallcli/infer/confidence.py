"""Decided or undetermined: when an answer may be relied upon, from the model's own validation.

A model card's ``confidence`` block holds, per answer (class) and per band of measured signal
(``window_signal_db``: the power of what changes the plot's bins together over the noise at a
person's frequencies, whole-wall light changes removed), the smallest probability at which that answer was right at least ``level`` of the time
on a validation set the model never trained on. An answer is confident when its probability
reaches the threshold of its class in its signal band; otherwise it is *undetermined*, with a
one-line reason. ``label`` and ``probabilities`` keep their meaning either way.

Why per class and per band: a probability means different things in different places. Where
the signal is at the noise, "nobody" is what the model says of an empty room and of a person it
cannot see, and only validation data with both can say how often it is right; a strong signal
with a "two people" answer fails in other ways. Thresholds are fitted on simulated validation
windows only (never on the clips a model is judged on), with a floor on the windows behind each
one, so that a cell too thin to measure stays undetermined rather than guessed.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from wallcli.wording import format_db, label_text, not_often_enough, under_threshold

FORMAT = "wallcli.confidence v1"
MIN_SUPPORT = 25  # validation windows a threshold must rest on
NO_BLOCK_REASON = "the model card states no validated confidence thresholds"
# "Nobody moves" (count's 0, activity's 'none') is never decided, by any task, at any signal: an
# empty room and a person too faint to see (farther away, dimmer light, smaller motion) give the
# same plot, and no validation set can say how often a user's rooms hold the second. The
# simulated calibration left out people under -20 dB, which made such answers look 97 % right;
# on the transfer set count decided "nobody" on 4 clips whose person was under the noise, all
# wrong. A measured signal above the plot's noise does not rescue it: codec residue and light
# changes read as a few dB on an empty wall (examples/empty.mp4: 3 dB), where activity's card
# certified 'none' and count's did not, so the two commands disagreed on the same clip.
NOBODY = (0, "none")
NOISE_FLOOR_DB = 0.0


def band_of(edges: list[float], snr_db: float) -> int:
    return int(np.searchsorted(np.asarray(edges, float), float(snr_db), side="right"))


def _band_text(edges: list[float], b: int) -> str:
    lo = f"{edges[b - 1]:g}" if b > 0 else None
    hi = f"{edges[b]:g}" if b < len(edges) else None
    if lo is None:
        return f"under {hi} dB"
    if hi is None:
        return f"{lo} dB and over"
    return f"{lo} to {hi} dB"


Z_ONE_SIDED_90 = 1.2816


def wilson_lower(hits: np.ndarray, n: np.ndarray, z: float) -> np.ndarray:
    """One-sided Wilson lower bound of a proportion hits/n."""
    n = np.asarray(n, np.float64)
    p = np.asarray(hits, np.float64) / np.maximum(n, 1)
    centre = p + z * z / (2 * n)
    spread = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return (centre - spread) / (1 + z * z / n)


def fit(probs: np.ndarray, labels: np.ndarray, snr_db: np.ndarray, classes: list[Any], *, level: float,
        edges: list[float], min_support: int = MIN_SUPPORT, z: float = Z_ONE_SIDED_90,
        groups: np.ndarray | None = None) -> dict[str, Any]:
    """The card's confidence block from validation windows: (n, k) probabilities, true class
    indices, measured signal (dB). For each (band, answer) the smallest threshold t such that the
    windows answered so with p >= t are right >= ``level`` of the time, with 90 % confidence (the
    one-sided Wilson lower bound of their accuracy, not the accuracy itself: the lowest threshold
    whose sample just meets the level is, by its choice, a lucky sample), and number >= min_support;
    None where no such t exists.

    ``groups`` (n,): which validation set (simulator, domain) each window comes from. A threshold
    must then also hold in every set on its own: in each set with at least min_support windows
    above it, those are right >= ``level`` of the time. Pooling lets a large easy set hide a
    small hard one; a decision that fails in one simulated world is a decision that may fail in a
    room none of them drew."""
    probs = np.asarray(probs, np.float64)
    labels = np.asarray(labels, np.int64)
    pred = probs.argmax(1)
    pmax = probs.max(1)
    bands = np.array([band_of(edges, s) for s in snr_db])
    grp = np.zeros(len(labels), np.int64) if groups is None else np.asarray(groups)
    table = []
    for b in range(len(edges) + 1):
        row = []
        for c in range(len(classes)):
            sel = (bands == b) & (pred == c)
            p, ok, g = pmax[sel], (labels[sel] == c), grp[sel]
            order = np.argsort(-p, kind="stable")
            p, ok, g = p[order], ok[order], g[order]
            # precision of the top-m answers for every m; the threshold is the lowest p whose
            # top set still meets the level (and every larger set of them does not need to)
            hits = np.cumsum(ok)
            m = np.arange(1, len(p) + 1)
            good = (wilson_lower(hits, m, z) >= level) & (m >= min_support)
            for u in np.unique(g) if groups is not None else []:
                n_u, h_u = np.cumsum(g == u), np.cumsum((g == u) & ok)
                good &= (n_u < min_support) | (h_u >= level * n_u)
            if not good.any():
                row.append(None)
                continue
            j = int(np.flatnonzero(good).max())
            row.append(round(float(p[j]), 4))
        table.append(row)
    return {"format": FORMAT, "level": level, "signal_edges_db": list(edges), "thresholds": table,
            "min_support": min_support, "bound": f"one-sided Wilson lower bound, z = {z:g}",
            **({} if groups is None else {"per_set": f"and >= level in each of the {len(np.unique(grp))} validation "
                                                    f"sets on its own (where >= min_support windows)"}),
            "thresholds_axes": "rows: signal bands (under the first edge, between edges, over the last); columns: "
                               "answers in the order of classes; null: never right that often"}


def judge(block: dict[str, Any] | None, probs, snr_db: float, classes: list[Any]) -> tuple[bool, str | None]:
    """(confident, reason) for one answer (its probabilities and measured signal)."""
    if not block:
        return False, NO_BLOCK_REASON
    probs = np.asarray(probs, np.float64)
    k = int(probs.argmax())
    edges = block["signal_edges_db"]
    b = band_of(edges, snr_db)
    t = block["thresholds"][b][k]
    level = block["level"]
    label = classes[k]
    what = label_text(label)
    # 'signal' names the figure: the window's signal_db, not the per-pixel SNR of `wallcli snr`
    if label in NOBODY:
        seen = ("no movement above the camera's noise" if snr_db < NOISE_FLOOR_DB
                else f"'{what}' is never decided")
        return False, (f"{seen} (signal {format_db(snr_db)} dB): an empty room and a person too "
                       "faint to show give the same plot")
    if t is None:
        return False, not_often_enough(what, snr_db, level, _band_text(edges, b))
    if probs[k] < t:
        return False, under_threshold(float(probs[k]), what, snr_db, level, t)
    return True, None


def validate_block(block: Any, n_classes: int) -> str | None:
    """A message naming what is wrong with a card's confidence block, or None when it is usable."""
    if not isinstance(block, dict):
        return "confidence must be an object"
    level, edges, table = block.get("level"), block.get("signal_edges_db"), block.get("thresholds")
    if not isinstance(level, (int, float)) or isinstance(level, bool) or not 0 < level <= 1:
        return "confidence.level must be a number in (0, 1]"
    if (not isinstance(edges, list) or not all(isinstance(e, (int, float)) and not isinstance(e, bool)
                                               and np.isfinite(e) for e in edges) or sorted(edges) != edges):
        return "confidence.signal_edges_db must be an increasing list of finite numbers"
    if not isinstance(table, list) or len(table) != len(edges) + 1:
        return "confidence.thresholds must have one row per signal band"
    for row in table:
        if not isinstance(row, list) or len(row) != n_classes:
            return "confidence.thresholds rows must have one entry per class"
        for t in row:
            if t is not None and (not isinstance(t, (int, float)) or isinstance(t, bool) or not 0 <= t <= 1):
                return "confidence.thresholds entries must be null or numbers in [0, 1]"
    return None
