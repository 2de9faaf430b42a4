"""How well a model does on a simulator dataset, and how sure we are of it (numpy only).

Used by ``wallcli train`` (the card's validation block) and ``research/evaluate.py``.

Two things a bare accuracy hides:

- *Visibility.* A person 4 m away in a dim room can change the plot 20 dB less than the
  camera's noise and nuisances; no detector sees that. Each dataset window records its movers'
  noise-free SNR in the plot that was actually recorded (``snr_db_weakest``: the least visible
  mover), so accuracy is reported on every window, on the visible ones (nobody moving, or every
  mover at least ``visible_db``), and per SNR band.
- *Clustering.* Windows cut from one scene share its room, camera and people, so their errors
  come together: 512 windows from 128 scenes are worth far fewer than 512 independent ones.
  The 95 % intervals resample whole scenes with replacement (cluster bootstrap).
"""
from __future__ import annotations

from typing import Any

import numpy as np

SNR_EDGES = [-np.inf, -20.0, -10.0, 0.0, 10.0, np.inf]
VISIBLE_DB = -10.0


def confusion(labels: np.ndarray, pred: np.ndarray, k: int) -> np.ndarray:
    cm = np.zeros((k, k), np.int64)
    np.add.at(cm, (np.asarray(labels, np.int64), np.asarray(pred, np.int64)), 1)
    return cm


def visible_mask(visibility: np.ndarray, visible_db: float = VISIBLE_DB) -> np.ndarray:
    """Windows with nobody moving (NaN) or every mover at least ``visible_db``."""
    return np.isnan(visibility) | (np.nan_to_num(visibility, nan=-np.inf) >= visible_db)


def scene_bootstrap(correct: np.ndarray, scenes: np.ndarray, n: int = 2000, seed: int = 0) -> list[float] | None:
    """95 % interval of the accuracy, resampling whole scenes with replacement."""
    if len(correct) == 0:
        return None
    uniq, inv = np.unique(scenes, return_inverse=True)
    right = np.bincount(inv, weights=np.asarray(correct, np.float64), minlength=len(uniq))
    total = np.bincount(inv, minlength=len(uniq)).astype(np.float64)
    pick = np.random.default_rng(seed).integers(0, len(uniq), (n, len(uniq)))
    acc = right[pick].sum(axis=1) / total[pick].sum(axis=1)
    return [float(v) for v in np.quantile(acc, [0.025, 0.975])]


def paired_difference(correct_a: np.ndarray, correct_b: np.ndarray, scenes: np.ndarray, n: int = 2000,
                      seed: int = 0) -> dict[str, Any]:
    """Accuracy of model a minus model b on the same windows, with the 95 % interval of a scene
    bootstrap of the pairs: far tighter than comparing two intervals, since both models meet
    the same hard scenes."""
    if len(correct_a) == 0:
        return {"difference": None, "difference_95ci": None}
    uniq, inv = np.unique(scenes, return_inverse=True)
    diff = np.bincount(inv, weights=np.asarray(correct_a, np.float64) - np.asarray(correct_b, np.float64),
                       minlength=len(uniq))
    total = np.bincount(inv, minlength=len(uniq)).astype(np.float64)
    pick = np.random.default_rng(seed).integers(0, len(uniq), (n, len(uniq)))
    boot = diff[pick].sum(axis=1) / total[pick].sum(axis=1)
    return {"difference": float(diff.sum() / total.sum()),
            "difference_95ci": [float(v) for v in np.quantile(boot, [0.025, 0.975])]}


def breakdown(probs: np.ndarray, labels: np.ndarray, visibility: np.ndarray | None, scenes: np.ndarray,
              visible_db: float = VISIBLE_DB) -> dict[str, Any]:
    """Accuracy with its scene-bootstrap interval, confusion matrix and recall, the same on visible
    windows, and accuracy per band of the least visible mover's SNR.

    visibility: per window, the least visible mover's SNR in dB (NaN: nobody moving); None when
    the dataset does not record it (the visible and per-SNR figures are then left out).
    scenes: per window, an id of the scene it was cut from.
    """
    labels = np.asarray(labels, np.int64)
    pred = np.asarray(probs).argmax(axis=1)
    k = np.asarray(probs).shape[1]
    ok = pred == labels
    cm = confusion(labels, pred, k)
    out = {
        "windows": int(len(labels)), "scenes": int(len(np.unique(scenes))),
        "accuracy": float(ok.mean()) if len(ok) else float("nan"),
        "accuracy_95ci": scene_bootstrap(ok, scenes),
        "confusion_matrix": cm.tolist(),
        "recall": [float(cm[i, i] / cm[i].sum()) if cm[i].sum() else None for i in range(k)],
    }
    if visibility is None:
        return out
    movers = ~np.isnan(visibility)
    vis = visible_mask(visibility, visible_db)
    bands = []
    for lo, hi in zip(SNR_EDGES[:-1], SNR_EDGES[1:]):
        sel = movers & (visibility >= lo) & (visibility < hi)
        if sel.any():
            bands.append({"snr_db": [None if np.isinf(lo) else lo, None if np.isinf(hi) else hi],
                          "windows": int(sel.sum()), "accuracy": float(ok[sel].mean())})
    return {
        **out,
        "nobody_moving_accuracy": float(ok[~movers].mean()) if (~movers).any() else None,
        "visible": {"min_snr_db": visible_db, "windows": int(vis.sum()), "scenes": int(len(np.unique(scenes[vis]))),
                    "accuracy": float(ok[vis].mean()) if vis.any() else None,
                    "accuracy_95ci": scene_bootstrap(ok[vis], scenes[vis]),
                    "confusion_matrix": confusion(labels[vis], pred[vis], k).tolist()},
        "accuracy_by_snr": bands,
    }


def clip_breakdown(probs: np.ndarray, labels: np.ndarray, visibility: np.ndarray | None, scenes: np.ndarray,
                   visible_db: float = VISIBLE_DB) -> dict[str, Any]:
    """Accuracy per scene, scored the way ``wallcli count``/``activity`` answer for a whole clip:
    the mean of the scene's window probabilities. A scene is visible when all its windows are.

    Scenes whose windows disagree on the label (none in the simulator's datasets) are left out
    and counted in ``mixed_label_scenes``; the intervals resample scenes, each one clip.
    """
    probs, labels = np.asarray(probs, np.float64), np.asarray(labels, np.int64)
    uniq, inv = np.unique(scenes, return_inverse=True)
    n, k = len(uniq), probs.shape[1]
    mean = np.zeros((n, k))
    np.add.at(mean, inv, probs)
    mean /= np.bincount(inv, minlength=n)[:, None]
    lo = np.full(n, np.iinfo(np.int64).max)
    hi = np.full(n, np.iinfo(np.int64).min)
    np.minimum.at(lo, inv, labels)
    np.maximum.at(hi, inv, labels)
    keep = lo == hi
    ok = mean.argmax(1) == lo
    ids = np.arange(n)
    out = {"clips": int(keep.sum()), "mixed_label_scenes": int((~keep).sum()),
           "accuracy": float(ok[keep].mean()) if keep.any() else None,
           "accuracy_95ci": scene_bootstrap(ok[keep], ids[keep])}
    if visibility is not None:
        seen = np.ones(n, bool)
        np.logical_and.at(seen, inv, visible_mask(visibility, visible_db))
        sel = keep & seen
        out["visible"] = {"min_snr_db": visible_db, "clips": int(sel.sum()),
                          "accuracy": float(ok[sel].mean()) if sel.any() else None,
                          "accuracy_95ci": scene_bootstrap(ok[sel], ids[sel])}
    return out
