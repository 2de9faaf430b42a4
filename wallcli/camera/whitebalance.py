"""Auto white balance hunting found per colour and divided out, before the grey corrections.

A camera that re-estimates the illuminant's colour moves each colour's gain slowly and its own
way (a few per cent over seconds). The exposure and drift fit (:mod:`wallcli.camera.exposure`)
works on the colours summed, a gain common to all three; what differs between the colours was
left in every profile, a whole-wall colour wave tens of times a person's signal, and the
networks read it as one (issue 36: most clips' answers lost to a 1-3 % hunt).

Each colour's share of the light, ``log(raw_c / mean over colours)`` per bin, stays constant on
a still wall whatever the light's level does; a person changes it by a small part of their
0.1-1 % and unevenly along the wall. The same fit as the exposure's (steps and a cubic drift,
kept only where most bins in every profile moved alike, ``exposure._steps_and_drift``) runs on
each colour's share; what it finds is divided out of that colour. The grey fit then sees what
is left, the whole frame's gain.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from wallcli.camera.exposure import _steps_and_drift

DEGREE = 5  # a white balance hunts back and forth within a window: more than the light's cubic drift


def white_balance(raws: list[np.ndarray], rate: float, part: np.ndarray | None = None) -> tuple[np.ndarray, dict[str, Any]] | None:
    """The per-colour gains (T, 3) of one window's parts [(bins, T, 3) raw levels] (each colour's
    share of the light, relative to its mean over the window), and the ``corrections`` finding
    (``{"kind": "white_balance", "amplitude": [r, g, b]}``); None where no colour moved."""
    raw = np.concatenate([np.asarray(r, np.float64) for r in raws], axis=0)  # (K, T, 3)
    # the colours' mean as numpy's mean over the last axis sums them (ten times faster, same values)
    grey = (raw[..., 0] + raw[..., 1] + raw[..., 2]) / 3.0
    ok = np.all(raw > 1e-6 * max(float(np.abs(raw).max()), 1e-12), axis=(1, 2)) & (grey.min(axis=1) > 0)
    if ok.sum() < 4:
        return None
    if not ok.all():
        raw, grey = raw[ok], grey[ok]
    share = np.log(raw / grey[..., None])  # (K', T, 3)
    share -= share.mean(axis=1, keepdims=True)
    p = None if part is None else np.asarray(part)[ok]
    gains = np.zeros((raw.shape[1], 3))
    amp = [0.0, 0.0, 0.0]
    steps = 0
    for c in range(3):
        model, st, drift = _steps_and_drift(share[:, :, c].T, rate, p, DEGREE)
        if not (st or drift):
            continue
        gains[:, c] = model - model.mean()
        amp[c] = round(float(np.expm1((model.max() - model.min()) / 2)), 5)
        steps += len(st)
    if not any(amp):
        return None
    found: dict[str, Any] = {"kind": "white_balance", "amplitude": amp}
    if steps:
        found["steps"] = steps
    return np.exp(gains), found


def balance(raws: list[np.ndarray], rate: float, part: np.ndarray | None = None) -> dict[str, Any] | None:
    """:func:`white_balance`'s gains divided out of ``raws`` in place; its finding, or None."""
    found = white_balance(raws, rate, part)
    if found is None:
        return None
    for r in raws:
        r /= found[0][None]
    return found[1]


def merge(per_window: list[list[dict]]) -> list[dict[str, Any]]:
    """A clip's ``white_balance`` entry: each colour's largest amplitude over the windows, and in
    how many windows it was found."""
    wb = [f for fs in per_window for f in fs if f["kind"] == "white_balance"]
    if not wb:
        return []
    amp = np.max([f["amplitude"] for f in wb], axis=0)
    return [{"kind": "white_balance", "amplitude": [round(float(a), 5) for a in amp], "windows": len(wb)}]
