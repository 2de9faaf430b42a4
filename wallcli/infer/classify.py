"""Classification of space-time plots, files and live streams: the place that wires the stages.

A frame and a window pass each stage once, and no stage calls back up into one before it:

    decode (io.video) -> camera pipeline (camera.pipeline: repeats, overlays, fields)
      -> view check and noise-blend measure beside the rows (view.check, camera.tnr)
      -> rows (infer.stream) -> windows, corrections, nets (infer.windows)
      -> judge (infer.judge) -> the docs/contract.md words (infer.result)

A .npz plot enters at the windows. Everything here only hands one stage's output to the next.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Iterator

import numpy as np

from wallcli.camera import corrections as corr
from wallcli.errors import WallcliError
from wallcli.infer.judge import judge_view, with_view
from wallcli.infer.result import clip_result, window_record
from wallcli.infer.windows import WindowStream, plot_fps, plot_windows, stream_row, video_fps


def classify_plot(model, plot, *, stride: int, source: str, corrections: corr.Options = corr.Options()) -> dict[str, Any]:
    """The docs/contract.md result for a whole space-time plot (a .npz file, already in memory)."""
    windows = plot_windows(model, plot, stride=stride, source=source, corrections=corrections)
    result = clip_result(model, *windows, stride=stride, source=source, fps=plot_fps(plot, source))
    from wallcli.snr.column import plot_column_snr_db

    result["column_snr_db"] = plot_column_snr_db(plot)  # the headline figure (wallcli.snr.column)
    view = (plot.meta or {}).get("view")
    if isinstance(view, dict):  # the verdict of the video's check, kept by stplot
        from wallcli.view.check import ViewCheck

        result = with_view(result, ViewCheck.restore(view))
    return with_decode_findings(result, plot.meta)


def with_decode_findings(result: dict[str, Any], meta: dict | None) -> dict[str, Any]:
    """``result`` with what the decode of a plot's video found and took out (stplot keeps the camera
    pipeline's corrections, repeats and fields, and the noise blending in ``meta["corrections"]``),
    added as the video's own path adds them (:meth:`_Decode.result`): the same list, and no answer
    decided on a signal_db that blending makes an upper bound."""
    from wallcli.camera.tnr import bound_result

    found = [dict(c) for c in (meta or {}).get("corrections") or []]
    blended = [c for c in found if c["kind"] == "temporal_nr" and isinstance(c.get("lag1"), (int, float))]
    result["corrections"] += [c for c in found if c["kind"] != "temporal_nr"]
    return bound_result(result, blended[0] if blended else None)


class WindowClassifier(WindowStream):
    """The windows of a stream of rows, classified as they complete, and the clip's result.

    The streaming half of :func:`classify_video`, for callers that decode themselves: ``wallcli
    scan`` feeds one decode to a classifier per task (and to the SNR estimator).
    """

    def result(self, source: str, frames: int | None = None, fps: float | None = None) -> dict[str, Any]:
        """The docs/contract.md result; WallcliError when the stream was shorter than one window
        (quoting ``frames``, the video's decoded frames, where given). ``fps``: the video's rate as
        read (VideoReader.fps); default the container's (``native_fps``)."""
        return clip_result(self.model, *self.windows(str(source), frames), stride=self.stride, source=str(source),
                           fps=fps or self.native())


def _too_short_video(source: str, check, model, frames: int | None = None) -> WallcliError:
    """The too-short error of a video: the frames quoted are the file's (not the rows resampled to
    the model's rate), and the view check's verdict on them goes with it (``view`` on the error,
    and in its line): a clip too short to answer may still be no view of a wall."""
    n, fps = (check.seen if frames is None else frames), check.fps  # frames: the file's, repeats too
    view = check.summary()
    said = "usable" if view["usable"] else view["reason"]
    need = f"{model.window / model.fps:.2f} s"
    # worded as windows.too_short (and snr): "N frame(s) decoded", the file's own frames
    if fps:
        need = f"{int(np.ceil(model.window / model.fps * fps - 1e-6))} frames ({need})"
        exc = WallcliError(f"{source} is too short: {n} frame(s) decoded ({n / fps:.2f} s at {fps:g} fps); "
                           f"one window needs {need}; view: {said}")
    else:
        exc = WallcliError(f"{source} is too short: {n} frame(s) decoded; one window needs {need}; view: {said}")
    exc.view = view
    return exc


class _Decode:
    """One decode of a video as the windows read it: the camera pipeline's frames, with the view
    check and the noise-blend measure (and any ``taps``) fed the same frames beside the rows."""

    def __init__(self, model, reader, *, roi, corrections: corr.Options, taps=(), progress=None, vertical=False,
                 ahead: bool = False, column=None):
        from wallcli.camera.pipeline import CameraPipeline
        from wallcli.camera.tnr import TemporalNoise
        from wallcli.infer.stream import RowStream
        from wallcli.io.ahead import Ahead
        from wallcli.io.video import FrameTee
        from wallcli.view.check import ViewCheck

        self.model, self.reader = model, reader
        self.check, self.blend = ViewCheck(roi), TemporalNoise()
        # repeats (a DVR's padding) are missing samples: no tap, row or time sees them; nor do they
        # see an interlaced clip's fields at two instants, nor a burned-in overlay
        self.unique = CameraPipeline(reader, self.check)
        frames = FrameTee(self.unique, (self.check, self.blend, *taps))
        # ahead: the checks and taps in a thread of their own, beside the projection and the nets
        # (a whole-clip answer; --follow keeps one thread, each line judged on exactly its frames)
        self._ahead = Ahead(frames) if ahead else None
        self.rows = RowStream(self._ahead or frames, roi=roi, bins=model.bins, fps=model.fps, progress=progress,
                              vertical=vertical or "vertical" in model.input_names or corrections.light,
                              register=corrections.shake, column=column)

    def __enter__(self) -> "_Decode":
        return self

    def __exit__(self, *exc) -> None:
        if self._ahead is not None:  # a consumer that raised between frames: stop the thread
            self._ahead.close()

    def refuse_short(self, classifier, source: str) -> None:
        """Raise the too-short error (with the view's verdict) when not one window was complete."""
        if classifier.empty:
            self.check.fps = float(self.reader.info.fps or 0.0) or None
            raise _too_short_video(source, self.check, self.model, self.unique.decoded)

    def result(self, classifier, source: str) -> dict[str, Any]:
        """The clip's result, judged by the view check, with the pipeline's findings; where the
        camera blended its noise, signal_db is an upper bound."""
        from wallcli.camera.tnr import bound_result

        result = with_view(classifier.result(source, frames=self.unique.decoded, fps=video_fps(self.reader)),
                           self.check)
        result["corrections"] += self.unique.corrections()
        return bound_result(result, self.blend.correction())


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
    from wallcli.infer.stream import PlotThumbnail
    from wallcli.io.video import open_video

    from wallcli.snr.column import ColumnSnr

    classifier = WindowClassifier(model, stride, corrections=corrections)
    thumb = PlotThumbnail() if keep_plot else None
    # the headline figure, from the same decode: fed by the rows' own projection, which sums the
    # same frames' columns (as a tap it summed them again, 0.07 ms a 1080p frame)
    column = ColumnSnr(roi)
    with open_video(source, threads=threads) as reader:
        classifier.native_fps = lambda: video_fps(reader)  # the frames' own rate, as stplot records it
        for tap in (*taps, column):  # e.g. an SNR estimator, whose corrections need the video's own rate
            if getattr(tap, "wants_fps", False) and getattr(tap, "fps", None) is None:
                tap.fps = float(reader.info.fps)
        with _Decode(model, reader, roi=roi, corrections=corrections, taps=taps, progress=progress,
                     vertical=keep_plot, ahead=True, column=column) as decode:
            rows = decode.rows
            for t, row in rows:
                if thumb is not None:
                    thumb.push(t, row)
                classifier.push(t, stream_row(row, rows), rows.ref)
        decode.refuse_short(classifier, str(source))
    result = decode.result(classifier, str(source))
    result["column_snr_db"] = column.db()
    return result, (thumb.plot(rows, model.bins, model.fps) if thumb is not None else None)


def load_plot(source: str | Path, *, roi=None, threads: int = 0, bins: int = 64, progress=None):
    """A space-time plot from a ``wallcli stplot`` .npz or from any video input.

    The whole plot is in memory: the CLI classifies videos with :func:`classify_video`
    instead; the video case stays as the reference that the streaming path is tested against.
    """
    if str(source).lower().endswith(".npz"):
        from wallcli.io.arrays import load_npz
        from wallcli.signal.stplot import FORMAT, from_arrays

        from wallcli.errors import UsageError
        from wallcli.io.video import STREAM

        if roi is not None:
            raise UsageError("--roi applies to videos; a space-time plot already has its region")
        if STREAM.get() is not None:  # (count's and track's --stream) was ignored without a word
            raise UsageError("--stream applies to videos; a space-time plot already holds one stream's plots")
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
    from wallcli.camera.tnr import bound_result
    from wallcli.io.video import open_video
    from wallcli.snr.column import ColumnSnr, bins_column_snr_db

    # the classifier of classify_video, so that the lines are its windows (and its clip answer)
    classifier = WindowClassifier(model, stride, corrections=corrections)
    column = ColumnSnr(roi)  # the clip's headline figure, as classify_video measures it
    with open_video(source, threads=threads) as reader:
        classifier.native_fps = lambda: video_fps(reader)  # the frames' own rate, as stplot records it
        column.fps = float(reader.info.fps)
        # cleaned as in classify_video (a line lists no corrections of the clip's)
        decode = _Decode(model, reader, roi=roi, corrections=corrections, column=column)
        rows = decode.rows
        for t, row in rows:
            n = len(classifier.times)
            classifier.push(t, stream_row(row, rows), rows.ref)
            if len(classifier.times) > n:
                rec = window_record(model, classifier.times[-1], classifier.probs[-1], classifier.signal[-1])
                # the window's column SNR from its own plot bins, as count reads a .npz's (a window
                # is one of the figure's 256-sample chunks: about a millisecond)
                rec["column_snr_db"] = bins_column_snr_db(classifier.last_rows[:model.bins], model.fps, rows.roi[2])
                rec |= {"corrections": corr.merge([classifier.found[-1]])}
                # what the frames so far say of the noise (a window holds 256 of them)
                rec = judge_view(rec, decode.check.view(rec["start"], rec["end"]))
                yield bound_result(rec, decode.blend.correction())
        decode.refuse_short(classifier, str(source))
    result = decode.result(classifier, str(source))
    result["column_snr_db"] = column.db()  # the clip's, as count --json gives it
    if len(result["windows"]) > len(classifier.times):  # the end-aligned last window
        last = dict(result["windows"][-1])
        tail = classifier.windower.pending()
        last["column_snr_db"] = (bins_column_snr_db(tail[2][:model.bins], model.fps, rows.roi[2])
                                 if tail is not None else None)
        yield last
    yield result
