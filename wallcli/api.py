"""wallcli from Python: the analyses behind ``count``, ``activity``, ``track``, ``stplot`` and ``snr``.

Each function returns what its command writes: the object of ``--json`` (plain dicts, lists,
floats, with ``None`` where the JSON has ``null``) or, for :func:`stplot`, the arrays of the
``.npz`` with its metadata. The commands call the same functions and only parse options and print,
so a notebook and a shell script get the same answers from the same clip (docs/api.md).

``import wallcli`` stays cheap: this module is loaded on the first call (wallcli/__init__.py).
"""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Callable, Iterator, Optional, Sequence

Roi = Optional[Sequence[int]]


def count(source, *, model=None, stride: int | None = None, roi: Roi = None, threads: int = 0,
          activity_model=None, single_stage: bool = False, deflicker: bool = True, exposure: bool = True,
          shake: bool = True) -> dict[str, Any]:
    """How many people (0, 1, 2) move out of view: the object of ``wallcli count SOURCE --json``.

    ``source``: a video (path, URL) or a ``.npz`` written by ``wallcli stplot``.
    ``model``: an .onnx with its card beside it (default: the shipped one); ``threads``: onnxruntime's.
    """
    net = load_model("count", model, threads=threads, activity_model=activity_model, single_stage=single_stage)
    return plain(classify(net, source, stride=stride, roi=roi, corrections=_fixes(deflicker, exposure, shake))[0])


def activity(source, *, model=None, stride: int | None = None, roi: Roi = None, threads: int = 0,
             deflicker: bool = True, exposure: bool = True, shake: bool = True) -> dict[str, Any]:
    """none / walking / crouching / waving / jumping: the object of ``wallcli activity SOURCE --json``."""
    net = load_model("activity", model, threads=threads)
    return plain(classify(net, source, stride=stride, roi=roi, corrections=_fixes(deflicker, exposure, shake))[0])


def track(source, *, roi: Roi = None, view_width: float | None = None, threads: int = 0) -> dict[str, Any]:
    """Where along the wall each moving person's shade was: the object of ``wallcli track SOURCE --json``."""
    return plain(track_clip(source, roi=roi, view_width=view_width, threads=threads)[0])


def stplot(source, *, roi: Roi = None, bins: int = 64, mean: str = "clip", mean_seconds: float = 10.0,
           threads: int = 0) -> dict[str, Any]:
    """The space-time plots of a video: the arrays ``wallcli stplot SOURCE -o plots.npz`` writes
    (``horizontal`` and ``vertical``: positions x time x RGB, float32; ``time``: seconds; ``h_mean``,
    ``v_mean``, and ``shift`` where measured), and its metadata under ``"meta"``."""
    from wallcli.signal.stplot import to_arrays

    arrays, meta = to_arrays(compute_plot(source, roi=roi, bins=bins, mean=mean, mean_seconds=mean_seconds,
                                          threads=threads))
    return {**arrays, "meta": plain(meta)}


def snr(source, *, roi: Roi | str = None, max_pixels: int = 32768, threads: int = 0, deflicker: bool = True,
        exposure: bool = True, shake: bool = True) -> dict[str, Any]:
    """Signal and noise power per colour and block size: the object of ``wallcli snr SOURCE --json``
    (``roi="auto"``: the best rectangle of the frame, as ``--roi auto``)."""
    return plain(measure_snr(source, roi=roi, max_pixels=max_pixels, threads=threads,
                             corrections=_fixes(deflicker, exposure, shake)).result)


# ------------------------------------------------------------------ the pieces the commands share
def plain(obj: Any) -> Any:
    """``obj`` as its JSON reads back: numpy scalars and arrays as Python numbers and lists, tuples as
    lists, NaN and infinities as None (JSON has no NaN)."""
    from wallcli.io.jsonfile import plain as _plain

    return _plain(obj)


def _fixes(deflicker: bool, exposure: bool, shake: bool):
    from wallcli.camera.corrections import Options

    return Options(deflicker=deflicker, exposure=exposure, shake=shake)


def _roi(roi) -> tuple[int, int, int, int] | None:
    """(x, y, w, h) from a sequence or 'x,y,w,h'; ValueError for anything else."""
    if roi is None:
        return None
    parts = roi.replace(" ", "").split(",") if isinstance(roi, str) else list(roi)
    if len(parts) != 4:
        raise ValueError(f"roi must be four integers x, y, w, h (got {roi!r})")
    return tuple(int(p) for p in parts)  # type: ignore[return-value]


def load_model(task: str, path=None, *, threads: int = 0, activity_model=None, single_stage: bool = False):
    """The classifier ``count`` or ``activity`` answers with (count in two stages unless ``single_stage``)."""
    from wallcli.infer.twostage import load_classifier

    return load_classifier(task, path, threads=threads, activity_path=activity_model, single=single_stage)


def classify(model, source, *, stride: int | None = None, roi: Roi = None, corrections=None,
             progress: Callable[[int], None] | None = None, keep_plot: bool = False):
    """(result, plot) of ``model`` (:func:`load_model`) on a video or a ``.npz`` plot; ``plot`` is the
    plot a figure is drawn from (a bounded thumbnail for a video, and None unless ``keep_plot``)."""
    from wallcli.camera.corrections import Options
    from wallcli.infer.classify import classify_plot, classify_video, load_plot

    fixes = corrections if corrections is not None else Options()
    stride = int(stride or model.card["stride"])
    if str(source).lower().endswith(".npz"):
        st = load_plot(source, roi=_roi(roi), bins=model.bins)
        return classify_plot(model, st, stride=stride, source=str(source), corrections=fixes), st
    # decoded once and classified window by window: memory does not grow with the clip's length
    return classify_video(model, str(source), stride=stride, roi=_roi(roi), progress=progress,
                          keep_plot=keep_plot, corrections=fixes)


def track_clip(source, *, roi: Roi = None, view_width: float | None = None, threads: int = 0,
               progress: Callable[[int], None] | None = None, keep_plot: bool = False):
    """(result, plot) of ``wallcli track`` on a video or a ``.npz`` plot."""
    from wallcli.camera.corrections import Options
    from wallcli.infer.track import track_plot, track_video

    if str(source).lower().endswith(".npz"):
        from wallcli.infer.classify import load_plot

        return track_plot(load_plot(source, roi=_roi(roi)), str(source), view_width=view_width)
    return track_video(str(source), roi=_roi(roi), threads=threads, progress=progress, keep_plot=keep_plot,
                       view_width=view_width, corrections=Options(False, False, False))


@contextmanager
def _quiet(label: str, total: int | None) -> Iterator[Callable[[int], None]]:
    yield lambda n=1: None


def narrow_roi(roi, bins: int) -> str | None:
    """A warning when the ROI has fewer pixels on a side than the plots have bins: the bins then
    interpolate between the same few pixels, and the plot holds no more independent positions
    than pixels (a 10 px strip gives 64 bins of 10 pixels' worth)."""
    _, _, w, h = roi
    if min(w, h) >= bins:
        return None
    side = f"{w} px wide" if w <= h else f"{h} px high"
    return (f"the ROI ({w}x{h} px) is {side}, fewer pixels than its {bins} bins: neighbouring bins share "
            f"pixels, so the plots hold at most {min(w, h)} independent positions (use a larger ROI or --bins)")


def compute_plot(source, *, roi: Roi = None, bins: int = 64, mean: str = "clip", mean_seconds: float = 10.0,
                 threads: int = 0, progress=_quiet):
    """The :class:`~wallcli.signal.stplot.StPlot` ``wallcli stplot`` writes; ``progress(label, frames)``
    is a context manager yielding a callable advanced once per frame. A too-narrow ROI's warning is
    in ``meta["warnings"]``."""
    from wallcli.camera.pipeline import CameraPipeline
    from wallcli.camera.tnr import TemporalNoise
    from wallcli.io.ahead import Ahead
    from wallcli.io.video import FrameTee, open_video
    from wallcli.signal.stplot import MODES, compute_stplot
    from wallcli.view.check import ViewCheck

    if mean not in MODES:
        raise ValueError(f"mean must be one of {MODES} (got {mean!r})")
    roi_t = _roi(roi)
    # the view check and the camera's shifts ride on the same decode: the .npz keeps both, so that
    # count and activity read from it answer as they would from the video (view verdict, shake)
    check, blend = ViewCheck(roi_t), TemporalNoise()
    with open_video(str(source), threads=threads) as reader:
        with progress("stplot", reader.info.frame_count) as advance:
            # repeats left out, interlaced fields at one instant, overlays masked, as count reads it
            # (its checks in a thread of their own, beside the projection: wallcli.io.ahead)
            # and the camera's blending of noise measured, as count measures it: the plot lists what
            # the decode found (repeats, fields, noise reduction) as the video's answers list it
            with Ahead(FrameTee(CameraPipeline(reader, check), (check, blend))) as frames:
                plot = compute_stplot(frames, roi=roi_t, bins=bins, mean=mean, mean_seconds=mean_seconds,
                                      progress=advance, register=True, view=check)
    if blend.correction():
        plot.meta.setdefault("corrections", []).append(blend.correction())
    narrow = narrow_roi(plot.meta["roi"], plot.bins)
    if narrow:
        plot.meta.setdefault("warnings", []).append(narrow)
    return plot


AUTO_MIN_PX = 64  # --roi auto's smallest side: the space-time plots' 64 bins, one pixel each


def measure_snr(source, *, roi: Roi | str = None, max_pixels: int = 32768, threads: int = 0, corrections=None,
                heatmap: bool = False, progress=_quiet) -> SimpleNamespace:
    """``wallcli snr``'s measurement: ``result`` (the ``--json`` object), ``res`` (the estimator's
    figures), ``grid`` (the cells a heatmap draws: with ``roi="auto"`` or ``heatmap``, else None),
    ``avoid`` (with ``roi="auto"``: the cells left out) and ``auto``."""
    import warnings

    from wallcli.camera.pipeline import CameraPipeline
    from wallcli.errors import WallcliError
    from wallcli.io.video import open_video
    from wallcli.signal.blocks import check_roi
    from wallcli.snr.estimate import SnrAccumulator, snr_db, snr_report
    from wallcli.snr.map import GridAccumulator
    from wallcli.view.check import ViewCheck

    source = str(source)
    auto = isinstance(roi, str) and roi.strip().lower() == "auto"
    roi_t = None if auto else _roi(roi)
    if auto and (source == "-" or not Path(source).exists()):
        raise WallcliError("--roi auto reads the video twice, so it needs a file (not '-' or a stream)"
                           if source == "-" or "://" in source else f"no such file: {source}")
    notes: list[str] = []
    grid = auto_snr = avoid = whole = None
    if auto:
        with open_video(source, threads=threads) as reader:
            full = check_roi(None, reader.info.width, reader.info.height)
            grid = GridAccumulator(full, 16, covariance=True)
            whole = ViewCheck()  # where the view fails (a mover, clipping) is no place for the ROI
            with progress("snr: finding the ROI", reader.info.frame_count) as advance:
                for frame in CameraPipeline(reader, whole).frames():
                    grid.update(frame.planes)
                    whole(frame)
                    advance()
        avoid = whole.avoid(grid.grid_roi, grid.rows, grid.cols)
        # a sliver makes fractional, overlapping bins of the same few pixels (a 10 px strip of
        # walking.mp4 turned count's 1 into 2): at least one pixel per bin, or the whole frame's side
        smallest = (-(-AUTO_MIN_PX // grid.ch), -(-AUTO_MIN_PX // grid.cw))
        try:
            roi_t, auto_snr = grid.best_roi(avoid, min_cells=smallest)
        except ValueError:
            notes.append("--roi auto: the view failed somewhere in every part of the frame (a mover "
                         "or clipping); the ROI was chosen as if it had not")
            roi_t, auto_snr = grid.best_roi(min_cells=smallest)
            avoid[:] = False
        if avoid.any():
            notes.append(f"--roi auto left out {int(avoid.sum())} of {avoid.size} cells where the view check saw "
                         "a moving object, clipping or black")
    with open_video(source, threads=threads) as reader, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        roi_c = check_roi(roi_t, reader.info.width, reader.info.height)
        acc = SnrAccumulator(roi_c, max_pixels=max_pixels, corrections=corrections, fps=float(reader.info.fps))
        if heatmap and grid is None:
            grid = GridAccumulator(roi_c, 48)
        feed_grid = grid if (grid is not None and not auto) else None
        check = ViewCheck(roi_c)
        # a repeated frame (a DVR's padding) is a missing sample: its zero difference is no noise;
        # interlaced fields are brought to one instant, overlays masked
        unique = CameraPipeline(reader, check)
        with progress("snr", reader.info.frame_count) as advance:
            for frame in unique.frames():
                acc.update(frame.planes)
                check(frame)
                if feed_grid is not None:
                    feed_grid.update(frame.planes)
                advance()
        fps = reader.fps  # the frames' own rate where it contradicts the container's
    notes += [str(w.message) for w in caught]
    result = snr_report(acc, source=source, fps=fps, notes=notes,
                        roi_mode="auto" if auto else ("given" if roi_t is not None else "frame"))
    result["corrections"] += unique.corrections()
    if unique.repeats.correction():  # "frames" stays the file's; the entry says how many the estimator left out
        result["frames"] = unique.decoded
    result["view"] = check.summary()
    if auto:
        result["auto"] = {"criterion": "max SNR of the rectangle's spatially averaged grey level",
                          "grid": [grid.rows, grid.cols], "snr_db": float(snr_db(auto_snr, 1.0)),
                          "avoided_cells": int(avoid.sum()),
                          "avoided": [k for k in ("moving object", "clipped", "too dark", "too little usable area")
                                      if k in whole.view()["issues"]] if avoid.any() else []}
    return SimpleNamespace(result=result, res=acc.result(), grid=grid, avoid=avoid, auto=auto)
