"""Sliding-window classification of space-time plots, files and live streams.

Windows of ``model.window`` samples at the model's canonical rate (30 fps) every ``stride``
samples, the last one aligned to the end of the clip (``window_starts``).  Each window goes
through ``normalize_window`` exactly as in training.

Clip-level probabilities are the mean of the window probabilities.  Averaging (rather than
a product of probabilities or a majority vote) keeps the answer a proper distribution,
weights every stretch of the clip equally, and degrades gracefully when one window is
confidently wrong; its argmax is the clip label.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Iterator

import numpy as np

from wallcli.errors import WallcliError
from wallcli.signal.window import StreamResampler, StreamWindower, normalize_window, resample, window_starts

CHUNK = 64  # windows normalised and run at a time, bounding memory on long clips


def _too_short(source: str, frames: int, model) -> WallcliError:
    return WallcliError(
        f"{source} is too short: {frames} frame(s) at {model.fps:g} fps ({frames / model.fps:.2f} s); "
        f"one window needs {model.window} frames ({model.window / model.fps:.2f} s)")


def _window_record(model, start: float, probs: np.ndarray) -> dict[str, Any]:
    k = int(np.argmax(probs))
    return {"start": round(float(start), 4), "end": round(float(start + model.window / model.fps), 4),
            "label": model.classes[k], "probabilities": [float(p) for p in probs]}


def resampled_plots(model, plot) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The plot's inputs for ``model`` at its canonical rate: ({name: (bins, T', 3)}, time (T',))."""
    if plot.bins != model.bins:
        raise WallcliError(f"the space-time plot has {plot.bins} bins, the model needs {model.bins}",
                           hint=f"recompute it with 'wallcli stplot --bins {model.bins}'")
    out, grid = {}, None
    for name in model.input_names:
        out[name], grid = resample(getattr(plot, name), plot.time, model.fps)
    return out, grid


def classify_plot(model, plot, *, stride: int, source: str) -> dict[str, Any]:
    """The CONTRACT.md result for a whole space-time plot."""
    plots, grid = resampled_plots(model, plot)
    frames = len(grid) if plot.frames >= 2 else plot.frames
    starts = window_starts(frames, model.window, stride)
    if not starts:
        raise _too_short(source, frames, model)
    probs = []
    for i in range(0, len(starts), CHUNK):
        chunk = starts[i:i + CHUNK]
        feed = {name: normalize_window(np.stack([p[:, s:s + model.window] for s in chunk]))
                for name, p in plots.items()}
        probs.append(model.predict(feed))
    probs = np.concatenate(probs)
    clip = probs.mean(axis=0)
    clip = clip / clip.sum()
    return {
        "input": source,
        "task": model.task,
        "model": model.info(),
        "fps": float(model.fps),
        "classes": model.classes,
        "label": model.classes[int(np.argmax(clip))],
        "probabilities": [float(p) for p in clip],
        "stride": int(stride),
        "window": model.window,
        "windows": [_window_record(model, grid[s], pr) for s, pr in zip(starts, probs)],
    }


def load_plot(source: str | Path, *, roi=None, threads: int = 0, bins: int = 64, progress=None):
    """A space-time plot from a ``wallcli stplot`` .npz or from any video input."""
    if str(source).lower().endswith(".npz"):
        from wallcli.io.arrays import load_npz
        from wallcli.signal.stplot import FORMAT, from_arrays

        if roi is not None:
            from wallcli.errors import UsageError

            raise UsageError("--roi applies to videos; a space-time plot already has its region")
        return from_arrays(*load_npz(source, kind=FORMAT), source=str(source))
    from wallcli.io.video import open_video
    from wallcli.signal.stplot import compute_stplot

    with open_video(source, threads=threads) as reader:
        return compute_stplot(reader, roi=roi, bins=bins, mean="clip", progress=progress)


def follow(model, source: str, *, stride: int, roi=None, threads: int = 0) -> Iterator[dict[str, Any]]:
    """One result per window, yielded as soon as its last frame is decoded.

    Rows are the raw (not mean-removed) plot rows: ``normalize_window`` removes each
    window's own mean, so no clip mean, which a live stream does not have, is needed.
    """
    from wallcli.io.video import open_video
    from wallcli.signal.blocks import check_roi
    from wallcli.signal.stplot import RowReducer

    names = model.input_names
    b = model.bins
    with open_video(source, threads=threads) as reader:
        info = reader.info
        reduce = RowReducer(check_roi(roi, info.width, info.height), b)
        resampler = StreamResampler(model.fps)
        windower = StreamWindower(model.window, stride)
        rows = 0
        for frame in reader.frames():
            h, v = reduce(frame.planes)
            for t, row in resampler.push(frame.time, np.concatenate([h, v])):
                rows += 1
                done = windower.push(t, row)
                if done is None:
                    continue
                start, _, win = done  # win: (2*bins, window, 3), horizontal rows first
                parts = {"horizontal": win[:b], "vertical": win[b:]}
                feed = {n: normalize_window(parts[n][None]) for n in names}
                yield _window_record(model, start, model.predict(feed)[0])
        if rows < model.window:
            raise _too_short(str(source), rows, model)
