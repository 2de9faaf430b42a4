"""Sliding-window classification of space-time plots, files and live streams.

Windows of ``model.window`` samples at the model's canonical rate (30 fps) every ``stride``
samples, the last one aligned to the end of the clip (``window_starts``).  Each window goes
through ``normalize_window`` (the version the model's card names) exactly as in training.

Clip-level probabilities are the mean of the window probabilities.  Averaging (rather than
a product of probabilities or a majority vote) keeps the answer a proper distribution,
weights every stretch of the clip equally, and degrades gracefully when one window is
confidently wrong; its argmax is the clip label.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Iterator

import numpy as np

from wallcli.camera import corrections as corr
from wallcli.errors import WallcliError
from wallcli.infer.confidence import judge
from wallcli.signal.window import StreamWindower, resample, run_window_starts, window_signal_db

CHUNK = 64  # windows normalised and run at a time, bounding memory on long clips


def _too_short(source: str, frames: int, model, fps: float | None = None) -> WallcliError:
    """``frames``: the file's own frames, as decoded (what snr and the report quote), at its own
    rate ``fps`` (None: the model's), not the resampled samples the windows are cut from."""
    fps = float(fps) if fps else float(model.fps)
    return WallcliError(
        f"{source} is too short: {frames} frame(s) decoded ({frames / fps:.2f} s at {fps:g} fps); "
        f"one window needs {model.window} frames at {model.fps:g} fps ({model.window / model.fps:.2f} s)")


def _too_short_video(source: str, check, model, frames: int | None = None) -> WallcliError:
    """The too-short error of a video: the frames quoted are the file's (not the rows resampled to
    the model's rate), and the view check's verdict on them goes with it (``view`` on the error,
    and in its line): a clip too short to answer may still be no view of a wall."""
    n, fps = (check.seen if frames is None else frames), check.fps  # frames: the file's, repeats too
    view = check.summary()
    said = "usable" if view["usable"] else view["reason"]
    need = f"{model.window / model.fps:.2f} s"
    # worded as _too_short (and snr): "N frame(s) decoded", the file's own frames
    if fps:
        need = f"{int(np.ceil(model.window / model.fps * fps - 1e-6))} frames ({need})"
        exc = WallcliError(f"{source} is too short: {n} frame(s) decoded ({n / fps:.2f} s at {fps:g} fps); "
                           f"one window needs {need}; view: {said}")
    else:
        exc = WallcliError(f"{source} is too short: {n} frame(s) decoded; one window needs {need}; view: {said}")
    exc.view = view
    return exc



def _judge(model, probs: np.ndarray, signal_db: float) -> tuple[bool, str | None]:
    block = model.card.get("confidence")
    confident, reason = judge(block, probs, signal_db, model.classes)
    if not block and model.no_block_reason():
        reason = model.no_block_reason()
    return confident, reason


def _gate(model, raw, probs, confident: bool, reason):
    """An activity answer where two people may be moving is not decided, whatever the net says
    (:class:`wallcli.infer.twostage.OnePersonActivity`); its reason replaces the model's."""
    if not hasattr(model, "gate"):
        return confident, reason
    why = model.gate(raw, model.classes[int(np.argmax(probs))])[1]
    return (False, why) if why else (confident, reason)


def _round(x):
    return None if x is None else round(float(x), 6)


def _window_record(model, start: float, raw: np.ndarray, signal_db: float) -> dict[str, Any]:
    """One window's answer from the model's raw output for it (for a two-stage count, both nets')."""
    probs = model.combine(raw)[0]
    k = int(np.argmax(probs))
    # judged on the figure the JSON carries, so that the reason quotes exactly that figure
    signal_db = round(float(signal_db), 2)
    confident, reason = _gate(model, raw, probs, *_judge(model, probs, signal_db))
    rec = {"start": round(float(start), 4), "end": round(float(start + model.window / model.fps), 4),
           "label": model.classes[k], "probabilities": [float(p) for p in probs],
           "confident": confident, "reason": reason, "signal_db": signal_db}
    stages = model.stages(raw)
    if stages is not None:
        rec["stages"] = stages
    if hasattr(model, "gate"):
        rec["two_people"] = _round(model.gate(raw, rec["label"])[0])
    return rec


def resampled_plots(model, plot, both: bool = False) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The plot's inputs for ``model`` at its canonical rate: ({name: (bins, T', 3)}, time (T',));
    ``both``: both plots, whatever the model reads (for the corrections)."""
    if plot.bins != model.bins:
        raise WallcliError(f"the space-time plot has {plot.bins} bins, the model needs {model.bins}",
                           hint=f"recompute it with 'wallcli stplot --bins {model.bins}'")
    out, grid = {}, None
    for name in (("horizontal", "vertical") if both else model.input_names):
        out[name], grid = resample(getattr(plot, name), plot.time, model.fps)
    return out, grid


def _result(model, times, probs, signal_db, *, stride: int, source: str, found=None) -> dict[str, Any]:
    """The docs/contract.md result from window start times, their probabilities (n, classes),
    measured signals (n,) in dB and what each window's corrections found (``found``)."""
    found = found if found is not None else [[] for _ in times]
    raw = probs.mean(axis=0)  # each net's mean over the windows (a two-stage count combines these)
    clip = model.combine(raw)[0]
    clip = clip / clip.sum()
    clip_db = round(float(np.mean(signal_db)), 2)
    confident, reason = _gate(model, raw, clip, *_judge(model, clip, clip_db))
    out = {
        "input": source,
        "task": model.task,
        "model": model.info(),
        "fps": float(model.fps),
        "classes": model.classes,
        "label": model.classes[int(np.argmax(clip))],
        "probabilities": [float(p) for p in clip],
        "confident": confident,
        "reason": reason,
        "signal_db": clip_db,
        "stride": int(stride),
        "window": model.window,
        "corrections": corr.merge(found),
        "windows": [_window_record(model, t, pr, db) | {"corrections": corr.merge([f])}
                    for t, pr, db, f in zip(times, probs, signal_db, found)],
    }
    if hasattr(model, "gate"):  # activity: how likely two people are, from the count net
        out["two_people"] = _round(model.gate(raw, out["label"])[0])
    if model.stages(raw) is not None:  # a two-stage count: what each stage found for the clip
        from wallcli.infer.twostage import stages_info

        out["stages"] = stages_info(model) | model.stages(raw)
    return out


def native_fps(time) -> float | None:
    """The frame rate of a plot's own timestamps (before resampling), None when unknown."""
    time = np.asarray(time, np.float64)
    if time.size < 3:
        return None
    d = float(np.median(np.diff(time)))
    return 1.0 / d if d > 0 else None


def _corrected(model, wins: dict, offsets: dict, native, options, starts=None, shifts=None):
    """(windows, findings per window): ``wins`` {name: (n, bins, W, 3)} with the whole-frame light
    nuisances of :mod:`wallcli.camera.corrections` divided out (all of a window's parts together),
    and the camera's shake regressed out where ``shifts`` (n, W, 2) were measured."""
    names = list(wins)
    if not options.any:
        return wins, [[] for _ in range(next(iter(wins.values())).shape[0])]
    parts, found = corr.correct_windows([wins[n] for n in names], [offsets[n] for n in names], model.fps,
                                        lines=corr.mains_lines(native, model.fps), options=options, starts=starts,
                                        vertical_index=names.index("vertical") if "vertical" in names else None,
                                        shifts=shifts)
    return dict(zip(names, parts)), found


def classify_plot(model, plot, *, stride: int, source: str, corrections: corr.Options = corr.Options()) -> dict[str, Any]:
    """The docs/contract.md result for a whole space-time plot (a .npz file, already in memory)."""
    from wallcli.io.video import check_rate

    if native_fps(plot.time) is not None:  # a plot of an older wallcli, made before videos were checked
        check_rate(native_fps(plot.time), source)
    plots, grid = resampled_plots(model, plot, both=corrections.light)
    shifts = None
    if corrections.shake and getattr(plot, "shift", None) is not None and plot.frames >= 2:
        # resampled as the profiles are, as the stream's extra row is (RowStream)
        ext = np.zeros((1, plot.frames, 3), np.float32)
        ext[0, :, :2] = plot.shift
        shifts = resample(ext, plot.time, model.fps)[0][0, :, :2].astype(np.float64)
    # the plot is its clip mean removed; that mean is the level offset normalisation v3 needs
    offsets = {"horizontal": np.asarray(plot.h_mean, np.float32), "vertical": np.asarray(plot.v_mean, np.float32)}
    starts = run_window_starts(grid, model.fps, model.window, stride)  # none spans a gap
    if not starts:
        raise _too_short(source, plot.frames, model, native_fps(plot.time))
    probs, signal, found = [], [], []
    native = native_fps(plot.time)
    for i in range(0, len(starts), CHUNK):
        chunk = starts[i:i + CHUNK]
        wins = {name: np.stack([p[:, s:s + model.window] for s in chunk]) for name, p in plots.items()}
        wins, f = _corrected(model, wins, {n: offsets[n][None] for n in wins}, native, corrections,
                             starts=[grid[s] for s in chunk],
                             shifts=None if shifts is None else np.stack([shifts[s:s + model.window] for s in chunk]))
        found += f
        wins = {name: wins[name] for name in model.input_names}
        probs.append(model.classify(wins, {name: offsets[name][None] for name in wins}))
        signal.append(window_signal_db([(w, offsets[name][None]) for name, w in wins.items()]))
    result = _result(model, [grid[s] for s in starts], np.concatenate(probs), np.concatenate(signal),
                     stride=stride, source=source, found=found)
    view = (plot.meta or {}).get("view")
    if isinstance(view, dict):  # the verdict of the video's check, kept by stplot
        from wallcli.view.check import ViewCheck

        result = with_view(result, ViewCheck.restore(view))
    return result


def _predict_window(model, win: np.ndarray, ref: np.ndarray, *, start: float = 0.0, native=None,
                    options: corr.Options = corr.Options()) -> tuple[np.ndarray, float, list]:
    """(probabilities, signal dB, corrections found) of one (2*bins, window, 3) window, horizontal
    rows first; ``ref`` (2*bins, 3) is the level the stream's rows are relative to (RowStream.ref).
    A window of 2*bins + 1 rows carries each sample's measured camera shift (dx, dy) in its last
    (:func:`stream_row`)."""
    b = model.bins
    shifts = win[2 * b, :, :2][None].astype(np.float64) if win.shape[0] > 2 * b else None
    parts = {"horizontal": win[:b], "vertical": win[b:2 * b]}
    refs = {"horizontal": ref[None, :b], "vertical": ref[None, b:]}
    # the corrections read both profiles when the stream has them (a light's change is alike along
    # both; rolling-shutter bands run down the vertical one), whatever the model reads
    use = [n for n in ("horizontal", "vertical") if n in model.input_names or (options.any and np.any(parts[n]))]
    wins, found = _corrected(model, {n: parts[n][None] for n in use}, refs, native, options, starts=[start],
                             shifts=shifts)
    probs = model.classify({n: wins[n] for n in model.input_names}, refs)[0]
    return probs, float(window_signal_db([(wins[n], refs[n]) for n in model.input_names])[0]), found[0]


def stream_row(row: np.ndarray, rows) -> np.ndarray:
    """A :class:`RowStream` row as the windows keep it: with the stream's measured shift (dx, dy)
    as one more row when it registers its frames, for the corrections' shake regression."""
    if rows.shift is None:
        return row
    return np.concatenate([row, np.array([[rows.shift[0], rows.shift[1], 0.0]], np.float32)])


class WindowClassifier:
    """The windows of a stream of rows, classified as they complete, and the clip's result.

    The streaming half of :func:`classify_video`, for callers that decode themselves: ``wallcli
    scan`` feeds one decode to a classifier per task (and to the SNR estimator).  Rows are
    :class:`RowStream`'s (horizontal bins first, then vertical), pushed with that stream's ``ref``
    (the level they are relative to).
    """

    def __init__(self, model, stride: int, *, corrections: corr.Options = corr.Options(), native_fps=None):
        self.model, self.stride = model, int(stride)
        self.corrections, self.native_fps = corrections, native_fps  # native_fps: the video's own rate
        self.windower = StreamWindower(model.window, stride, model.fps)
        self.times, self.probs, self.signal, self.found = [], [], [], []
        self.ref = None

    def push(self, t: float, row: np.ndarray, ref: np.ndarray) -> None:
        self.ref = ref
        done = self.windower.push(t, row)
        if done is not None:
            p, db, f = _predict_window(self.model, done[2], ref, start=done[0], native=self.native_fps,
                                       options=self.corrections)
            self.times.append(done[0])
            self.probs.append(p)
            self.signal.append(db)
            self.found.append(f)

    @property
    def empty(self) -> bool:
        """No window so far, nor one at the end: the stream is too short to answer."""
        return not self.times and self.windower.pending() is None

    def result(self, source: str, frames: int | None = None) -> dict[str, Any]:
        """The docs/contract.md result; WallcliError when the stream was shorter than one window
        (quoting ``frames``, the video's decoded frames, where given)."""
        model, w = self.model, self.windower
        last = w.pending()
        if self.empty:
            raise _too_short(str(source), w.count if frames is None else frames, model,
                             None if frames is None else self.native_fps)
        times, probs, signal, found = list(self.times), list(self.probs), list(self.signal), list(self.found)
        if last is not None:  # window_starts' end-aligned window: the last `window` rows
            p, db, f = _predict_window(model, last[2], self.ref, start=last[0], native=self.native_fps,
                                       options=self.corrections)
            times.append(last[0])
            probs.append(p)
            signal.append(db)
            found.append(f)
        return _result(model, times, np.stack(probs), np.asarray(signal), stride=self.stride, source=str(source),
                       found=found)


def judge_view(rec: dict[str, Any], view: dict) -> dict[str, Any]:
    """``rec`` (a window or clip answer) with ``view``: where the view is not a static wall, the
    answer cannot be relied upon whatever the model says, and the view's reason replaces the model's."""
    rec["view"] = view
    if not view["usable"]:
        rec["confident"], rec["reason"] = False, view["reason"]
    return rec


def with_view(result: dict[str, Any], check) -> dict[str, Any]:
    """``result`` with the verdict of the view check (:class:`wallcli.view.check.ViewCheck`, fed
    the same decode) on each window and on the clip."""
    for w in result.get("windows", []):
        judge_view(w, check.view(w["start"], w["end"]))
    return judge_view(result, check.summary())


def classify_video(model, source: str, *, stride: int, roi=None, threads: int = 0, progress=None,
                   keep_plot: bool = False, taps=(), corrections: corr.Options = corr.Options()):
    """(result, plot) for a video, decoded once into windows classified as they complete.

    Gives the windows of :func:`classify_plot` on the same video (the end-aligned last one
    included), while holding only the last ``model.window`` resampled rows.  ``plot`` (for
    ``--plot``) is None unless ``keep_plot``; then it is a :class:`PlotThumbnail` copy of at most
    2048 time columns, enough to draw, not the full plot. ``taps`` (callables) also get every
    decoded frame (:class:`wallcli.io.video.FrameTee`), e.g. to measure the SNR in the same decode.
    The view check rides on the same decode; its verdict is in the result (:func:`with_view`).
    """
    from wallcli.camera.pipeline import CameraPipeline
    from wallcli.camera.tnr import TemporalNoise, bound_result
    from wallcli.infer.stream import PlotThumbnail, RowStream
    from wallcli.io.video import FrameTee, open_video
    from wallcli.view.check import ViewCheck

    classifier = WindowClassifier(model, stride, corrections=corrections)
    thumb = PlotThumbnail() if keep_plot else None
    check = ViewCheck(roi)
    blend = TemporalNoise()
    with open_video(source, threads=threads) as reader:
        classifier.native_fps = float(reader.info.fps)
        for tap in taps:  # e.g. an SNR estimator, whose corrections need the video's own rate
            if getattr(tap, "wants_fps", False) and getattr(tap, "fps", None) is None:
                tap.fps = float(reader.info.fps)
        # repeats (a DVR's padding) are missing samples: no tap, row or time sees them; nor do they
        # see an interlaced clip's fields at two instants, nor a burned-in overlay
        unique = CameraPipeline(reader, check)
        rows = RowStream(FrameTee(unique, (check, blend, *taps)), roi=roi, bins=model.bins, fps=model.fps,
                         progress=progress, vertical=keep_plot or "vertical" in model.input_names or corrections.light,
                         register=corrections.shake)
        for t, row in rows:
            if thumb is not None:
                thumb.push(t, row)
            classifier.push(t, stream_row(row, rows), rows.ref)
        if classifier.empty:
            check.fps = float(reader.info.fps or 0.0) or None
            raise _too_short_video(str(source), check, model, unique.decoded)
    result = with_view(classifier.result(str(source), frames=unique.decoded), check)
    result["corrections"] += unique.corrections()
    result = bound_result(result, blend.correction())  # a blended noise: signal_db an upper bound
    return result, (_thumb_plot(thumb, rows, model) if thumb is not None else None)


def _thumb_plot(thumb, rows, model):
    from wallcli.signal.stplot import StPlot

    b = model.bins
    cols, t = thumb.columns()
    mean = thumb.mean()
    x = (cols - mean).transpose(1, 0, 2).astype(np.float32)  # clip mean removed, as compute_stplot
    raw_mean = (mean + rows.ref).astype(np.float32)
    meta = {"source": str(rows.reader.info.source), "roi": list(rows.roi), "bins": b, "fps": float(model.fps),
            "downsample": thumb.factor}
    return StPlot(np.ascontiguousarray(x[:b]), np.ascontiguousarray(x[b:]), t, raw_mean[:b], raw_mean[b:], meta)


def load_plot(source: str | Path, *, roi=None, threads: int = 0, bins: int = 64, progress=None):
    """A space-time plot from a ``wallcli stplot`` .npz or from any video input.

    The whole plot is in memory: the CLI classifies videos with :func:`classify_video`
    instead; the video case stays as the reference that the streaming path is tested against.
    """
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


def follow(model, source: str, *, stride: int, roi=None, threads: int = 0,
           corrections: corr.Options = corr.Options()) -> Iterator[dict[str, Any]]:
    """One result per window, yielded as soon as its last frame is decoded; when the input ends
    (a file, a stream that closes), the end-aligned last window, then the clip's result (the
    object of :func:`classify_video`, with ``windows``): the same windows as the whole run.

    Rows are raw (not clip-mean-removed): ``normalize_window`` removes each window's own
    mean, so no clip mean, which a live stream does not have, is needed.
    """
    from wallcli.camera.pipeline import CameraPipeline
    from wallcli.camera.tnr import TemporalNoise, bound_result
    from wallcli.infer.stream import RowStream
    from wallcli.io.video import FrameTee, open_video
    from wallcli.view.check import ViewCheck

    # the classifier of classify_video, so that the lines are its windows (and its clip answer)
    classifier = WindowClassifier(model, stride, corrections=corrections)
    check = ViewCheck(roi)
    blend = TemporalNoise()
    with open_video(source, threads=threads) as reader:
        classifier.native_fps = float(reader.info.fps)
        # cleaned as in classify_video (a line lists no corrections of the clip's)
        unique = CameraPipeline(reader, check)
        rows = RowStream(FrameTee(unique, (check, blend)), roi=roi, bins=model.bins, fps=model.fps,
                         vertical="vertical" in model.input_names or corrections.light, register=corrections.shake)
        for t, row in rows:
            n = len(classifier.times)
            classifier.push(t, stream_row(row, rows), rows.ref)
            if len(classifier.times) > n:
                rec = _window_record(model, classifier.times[-1], classifier.probs[-1], classifier.signal[-1])
                rec |= {"corrections": corr.merge([classifier.found[-1]])}
                # what the frames so far say of the noise (a window holds 256 of them)
                yield bound_result(judge_view(rec, check.view(rec["start"], rec["end"])), blend.correction())
        if classifier.empty:
            check.fps = float(reader.info.fps or 0.0) or None
            raise _too_short_video(str(source), check, model, unique.decoded)
    result = with_view(classifier.result(str(source), frames=unique.decoded), check)
    result["corrections"] += unique.corrections()
    result = bound_result(result, blend.correction())
    if len(result["windows"]) > len(classifier.times):  # the end-aligned last window
        yield result["windows"][-1]
    yield result
