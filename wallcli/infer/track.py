"""``wallcli track``'s analysis: a clip's tracks from the same decode and camera pipeline as count.

The rows are count's (io.video -> camera pipeline -> view check -> rows at 30 fps, 64 bins); only
the horizontal ones are read, and a :class:`~wallcli.signal.track.TrackBuilder` keeps one chunk of
them, so memory does not grow with the clip's length. A .npz from ``wallcli stplot`` is tracked at
its own rate.
"""
from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

from wallcli.camera import corrections as corr
from wallcli.signal.track import GEOMETRY_BY_STRENGTH, GEOMETRY_SIGMA, TrackBuilder, simultaneous, track_rows

BINS, FPS = 64, 30.0
# what _Decode needs of a model: the rows' shape and rate (the tracker reads no net)
_ROWS = SimpleNamespace(bins=BINS, fps=FPS, window=256, input_names=["horizontal"])
MIN_SAMPLES = 60  # 2 s at 30 fps: a track lasts at least a second, and the background needs more
NONE_MOVES = "no moving person's shade on the wall: nobody moves, or too faintly to follow"


def track_result(source: str, tracks, *, fps: float, view_width: float | None = None, extra: dict | None = None) -> dict[str, Any]:
    """The ``wallcli track --json`` object of ``tracks`` (docs/contract.md)."""
    out = {"input": source, "task": "track", "fps": fps,
           "method": {"name": "wallcli-streaks", "unit": "fraction of the view's width at its mid-height",
                      "geometry_sigma": GEOMETRY_SIGMA,
                      # each sample's sigma: its sigma_shade with this, by the shade's strength (log-interpolated)
                      "geometry_sigma_by_strength": [list(p) for p in GEOMETRY_BY_STRENGTH]},
           "tracks": [t.as_dict(view_width) for t in tracks],
           "simultaneous": simultaneous(tracks)}
    if view_width is not None:
        out["view_width_m"] = view_width
    out["reason"] = None if tracks else NONE_MOVES
    out.update(extra or {})
    return out


def track_plot(plot, source: str, *, view_width: float | None = None):
    """(result, plot) for a .npz space-time plot (already in memory)."""
    rows = np.moveaxis(plot.horizontal, 0, 1)  # (T, bins, 3)
    t = np.asarray(plot.time, np.float64)
    if len(t) < 2 or t[-1] - t[0] < (MIN_SAMPLES - 1) / FPS:
        from wallcli.errors import WallcliError

        span = f"{t[-1] - t[0]:.2f} s" if len(t) else "no samples"
        raise WallcliError(f"{source} is too short: {len(t)} sample(s), {span}; tracking needs {MIN_SAMPLES / FPS:g} s")
    steps = np.diff(t)
    # the frames' own interval, not the span over the count: lost frames (a gap) are no slower rate
    fps = float(1.0 / np.median(steps[steps > 0])) if np.any(steps > 0) else FPS
    from wallcli.infer.windows import plot_fps

    fps = plot_fps(plot, source) or fps  # count's rule and refusal (io.rates.plot_rate): the video's rate
    extra, view = {}, None
    if isinstance((plot.meta or {}).get("view"), dict):  # the verdict of the video's check, kept by stplot
        from wallcli.view.check import ViewCheck

        # the same view block as the video's (and count's on this file): its summary, not the raw record
        view = ViewCheck.restore(plot.meta["view"]).summary()
        extra["view"] = view
    # what the video's decode found and took out (repeats, fields), as the video's track lists it
    extra["corrections"] = [c for c in (plot.meta or {}).get("corrections") or [] if c["kind"] != "temporal_nr"]
    gaps = [tuple(g) for g in (view or {}).get("gaps", [])]
    result = track_result(source, track_rows(rows, t, fps, gaps=gaps), fps=fps, view_width=view_width,
                          extra=extra)
    return _judged(result, view), plot


def _judged(result: dict[str, Any], view: dict | None) -> dict[str, Any]:
    """Where the view is no static wall, the tracks may be the camera's, not people's: the reason says so."""
    if view is not None and not view.get("usable", True):
        result["reason"] = f"view not usable: {view.get('reason')}"
    return result


def track_video(source: str, *, roi=None, threads: int = 0, progress=None, keep_plot: bool = False,
                view_width: float | None = None, corrections: corr.Options = corr.Options()):
    """(result, plot) for a video, decoded once; ``plot`` is a bounded thumbnail for drawing (or None)."""
    from wallcli.infer.classify import _Decode
    from wallcli.infer.stream import PlotThumbnail
    from wallcli.io.video import open_video

    thumb = PlotThumbnail() if keep_plot else None
    with open_video(source, threads=threads) as reader:
        builder = TrackBuilder(FPS, gaps=lambda: reader.gaps)  # rows across lost frames are interpolated
        with _Decode(_ROWS, reader, roi=roi, corrections=corrections, progress=progress, ahead=True) as decode:
            rows = decode.rows
            for t, row in rows:
                builder.push(t, row[:BINS])
                if thumb is not None:
                    thumb.push(t, row)
    result = _video_result(str(source), builder, decode, view_width)
    return result, (thumb.plot(rows, BINS, FPS) if thumb is not None else None)


def _video_result(source: str, builder: TrackBuilder, decode, view_width: float | None) -> dict[str, Any]:
    """The result of a decoded video's rows (WallcliError when too short to track), judged by its view."""
    if builder.samples < MIN_SAMPLES:
        from wallcli.errors import WallcliError

        raise WallcliError(f"{source} is too short: {decode.unique.decoded} frame(s) decoded; tracking needs "
                           f"{MIN_SAMPLES / FPS:g} s")
    view = decode.check.summary()
    extra = {"view": view, "corrections": decode.unique.corrections(), "duration": round(builder.samples / FPS, 3)}
    # fps: the video's rate (as snr and count report it); the rows are at FPS
    return _judged(track_result(source, builder.finish(), fps=float(decode.reader.fps), view_width=view_width,
                                extra=extra), view)


def track_csv(result: dict) -> str:
    """One row per track sample: track,t,x,sigma[,x_m]."""
    metres = "view_width_m" in result
    lines = ["track,t,x,sigma" + (",x_m" if metres else "")]
    for tr in result["tracks"]:
        for s in tr["samples"]:
            lines.append(f"{tr['id']},{s['t']},{s['x']},{s['sigma']}" + (f",{s['x_m']}" if metres else ""))
    return "\n".join(lines) + "\n"


def follow_tracks(source: str, *, roi=None, threads: int = 0, view_width: float | None = None,
                  corrections: corr.Options = corr.Options()):
    """``--follow``: each track's new samples as soon as a chunk of rows is read (one object per track
    and chunk: ``{"id", "samples"}``), then the whole clip's result (the object of ``--json``)."""
    from wallcli.infer.classify import _Decode
    from wallcli.io.video import open_video

    builder = None
    said: dict[int, int] = {}  # samples already printed, per track

    def news():
        for k in builder.tracks:
            n = said.get(k.id, 0)
            if len(k.t) > n:
                said[k.id] = len(k.t)
                yield {"id": k.id, "samples": k.as_dict(view_width)["samples"][n:]}

    with open_video(source, threads=threads) as reader:
        builder = TrackBuilder(FPS, gaps=lambda: reader.gaps)
        decode = _Decode(_ROWS, reader, roi=roi, corrections=corrections)
        for t, row in decode.rows:
            builder.push(t, row[:BINS])
            yield from news()
    result = _video_result(str(source), builder, decode, view_width)  # finishes the last chunk
    yield from news()
    yield result
