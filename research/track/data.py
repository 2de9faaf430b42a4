"""The recordings with motion-capture truth, as the tracker sees them: each clip's whole horizontal
and vertical plots (rebuilt from the cached inference windows, so the camera pipeline and the 30 fps
resampling are the commands' own) and each person's place along the wall per sample.

``x`` is the truth README's fraction of the view's width at its mid-height (0 = left edge, 1 = right
edge); a person beyond the view has x outside [0, 1]."""
from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "recordings"))
from common import TRANSFER, K, band, recordings  # noqa: E402
from wallcli.train.recordings import FPS, WINDOW, fold_of  # noqa: E402


@dataclass
class Clip:
    name: str
    fold: int
    people: int
    persons: int
    activity: str
    activities: list[str]
    snr_db: float | None
    detectable: bool | None
    band: str
    h: np.ndarray  # (T, bins, 3) raw levels, 30 fps
    v: np.ndarray
    x: np.ndarray  # (persons, T) fraction of the view's width (nan: not logged)
    moving: np.ndarray  # (persons, T) bool: the person moves at this sample
    person_act: list[str]


def full_plot(win: np.ndarray, off: np.ndarray, starts: np.ndarray, frames: int) -> np.ndarray:
    out = np.zeros((frames, win.shape[1], 3), np.float32)
    for w, o, s in zip(win, off, starts):
        out[s:s + WINDOW] = np.moveaxis(w, 1, 0) + o[None]
    return out


def truth_x(name: str, samples: int):
    f = TRANSFER / "truth" / (Path(name).stem + ".json")
    if not f.is_file():
        return None
    d = json.loads(f.read_text())
    c = np.array(d["view_corners_on_wall_xy"], float)
    # the left corners are the two of least x
    order = np.argsort(c[:, 0])
    left, right = c[order[:2], 0].mean(), c[order[2:], 0].mean()
    ids = [p["id"] for p in d["people"]]
    acts = [p["activity"] for p in d["people"]]
    tf = np.array([fr["t"] for fr in d["per_frame"]])
    xs = np.full((len(ids), len(tf)), np.nan)
    ys = np.full((len(ids), len(tf)), np.nan)
    for j, fr in enumerate(d["per_frame"]):
        for p in fr["people"]:
            k = ids.index(p["id"])
            xs[k, j] = (p["position"][0] - left) / (right - left)
            ys[k, j] = np.mean(np.array(p["bbox_max"]) - np.array(p["bbox_min"]))
    t = np.arange(samples) / FPS
    x = np.stack([np.interp(t, tf, xs[k]) for k in range(len(ids))]) if ids else np.zeros((0, samples))
    # moving: the body's box or place changes (a person standing still does not)
    mv = []
    for k in range(len(ids)):
        sp = np.abs(np.gradient(xs[k])) * d["fps"] + np.abs(np.gradient(ys[k])) * d["fps"]
        mv.append(np.interp(t, tf, (sp > 1e-3).astype(float)) > 0.5)
    moving = np.array(mv, bool).reshape(len(ids), samples)
    return x, moving, acts


def clips(need_truth: bool = True) -> list[Clip]:
    out = []
    for r in recordings():
        T = r.frames
        tx = truth_x(r.name, T)
        if tx is None and need_truth:
            continue
        x, moving, acts = tx if tx is not None else (np.zeros((0, T)), np.zeros((0, T), bool), [])
        h = full_plot(r.horizontal, r.h_offset, r.starts, T)
        v = full_plot(r.vertical, r.v_offset, r.starts, T)
        out.append(Clip(r.name, fold_of(r.name, K), r.people, r.persons, r.activity, acts, r.snr_db, r.detectable,
                        band(r), h, v, x, moving, acts))
    return out
