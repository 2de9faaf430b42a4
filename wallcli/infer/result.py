"""The words stage: the docs/contract.md objects, one per window and one for the clip, from what
the windows stage measured (starts, the nets' raw outputs, signals, corrections found), each
answer judged (:mod:`wallcli.infer.judge`).

Clip-level probabilities are the mean of the window probabilities.  Averaging (rather than
a product of probabilities or a majority vote) keeps the answer a proper distribution,
weights every stretch of the clip equally, and degrades gracefully when one window is
confidently wrong; its argmax is the clip label.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from wallcli.camera import corrections as corr
from wallcli.infer.judge import judge_answer


def _round(x):
    return None if x is None else round(float(x), 6)


def window_record(model, start: float, raw: np.ndarray, signal_db: float) -> dict[str, Any]:
    """One window's answer from the model's raw output for it (for a two-stage count, both nets')."""
    probs = model.combine(raw)[0]
    k = int(np.argmax(probs))
    # judged on the figure the JSON carries, so that the reason quotes exactly that figure
    signal_db = round(float(signal_db), 2)
    confident, reason = judge_answer(model, raw, probs, signal_db)
    rec = {"start": round(float(start), 4), "end": round(float(start + model.window / model.fps), 4),
           "label": model.classes[k], "probabilities": [float(p) for p in probs],
           "confident": confident, "reason": reason, "signal_db": signal_db}
    stages = model.stages(raw)
    if stages is not None:
        rec["stages"] = stages
    if hasattr(model, "gate"):
        rec["two_people"] = _round(model.gate(raw, rec["label"])[0])
    return rec


def clip_result(model, times, probs, signal_db, found=None, *, stride: int, source: str,
                fps: float | None = None) -> dict[str, Any]:
    """The docs/contract.md result from window start times, their probabilities (n, classes),
    measured signals (n,) in dB and what each window's corrections found (``found``). ``fps``: the
    video's frame rate (what ``"fps"`` reports, as snr does); the windows' samples are at the model's
    rate, ``"window_fps"``."""
    found = found if found is not None else [[] for _ in times]
    raw = probs.mean(axis=0)  # each net's mean over the windows (a two-stage count combines these)
    clip = model.combine(raw)[0]
    clip = clip / clip.sum()
    clip_db = round(float(np.mean(signal_db)), 2)
    confident, reason = judge_answer(model, raw, clip, clip_db)
    out = {
        "input": source,
        "task": model.task,
        "model": model.info(),
        "fps": float(fps) if fps else float(model.fps),
        "window_fps": float(model.fps),
        "classes": model.classes,
        "label": model.classes[int(np.argmax(clip))],
        "probabilities": [float(p) for p in clip],
        "confident": confident,
        "reason": reason,
        "signal_db": clip_db,
        "stride": int(stride),
        "window": model.window,
        "corrections": corr.merge(found),
        "windows": [window_record(model, t, pr, db) | {"corrections": corr.merge([f])}
                    for t, pr, db, f in zip(times, probs, signal_db, found)],
    }
    if hasattr(model, "gate"):  # activity: how likely two people are, from the count net
        out["two_people"] = _round(model.gate(raw, out["label"])[0])
    if model.stages(raw) is not None:  # a two-stage count: what each stage found for the clip
        from wallcli.infer.twostage import stages_info

        out["stages"] = stages_info(model) | model.stages(raw)
    return out
