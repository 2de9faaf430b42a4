"""One video, one decode, every task asked for.

Each decoded frame goes to the SNR estimator (its planes, as in ``wallcli snr``) and to the
space-time rows (:class:`~wallcli.infer.stream.RowStream`, as ``wallcli count``/``activity`` read a
video), whose windows go to one :class:`~wallcli.infer.classify.WindowClassifier` per
classification task. Same frames, same functions, same defaults (the whole frame, the model
card's stride) as the single-video commands, so the answers are theirs, for a third of the
decoding. Memory stays flat in the video's length, as theirs does.
"""
from __future__ import annotations

from typing import Any, Callable

TASKS = ("count", "activity", "snr")
CLASSIFY = ("count", "activity")


class _Tee:
    """A reader whose frames also go to ``each`` on their way to the reader's consumer."""

    def __init__(self, reader, each: Callable):
        self.reader, self.info, self.each = reader, reader.info, each

    def frames(self):
        for frame in self.reader.frames():
            self.each(frame)
            yield frame


def analyse(source: str, tasks, models: dict, *, decoder_threads: int = 0,
            on_frame: Callable[[], None] | None = None, corrections=None) -> dict[str, Any]:
    """``{"frames", "duration", "fps", "warnings", "view", <task>: <its --json object>, ...}`` for ``source``.

    ``models``: a loaded :class:`~wallcli.infer.model.Model` per classification task asked for.
    ``corrections``: :class:`~wallcli.camera.corrections.Options` (default: all on); what they
    found is in each task's object and, for the video, under ``"corrections"`` (the first task's).
    ``on_frame`` is called after every decoded frame (a watchdog's heartbeat; it may raise to
    abandon the video). Raises WallcliError when the video cannot be read or is too short for a
    task: a video either has every answer asked for or none.
    """
    from wallcli.camera.corrections import Options
    from wallcli.camera.pipeline import CameraPipeline
    from wallcli.camera.tnr import TemporalNoise, bound_result
    from wallcli.errors import WallcliError
    from wallcli.infer.classify import WindowClassifier
    from wallcli.infer.judge import with_view
    from wallcli.infer.stream import RowStream
    from wallcli.infer.windows import stream_row
    from wallcli.io.video import open_video
    from wallcli.signal.blocks import check_roi
    from wallcli.snr.estimate import SnrAccumulator, snr_report
    from wallcli.view.check import ViewCheck

    classify = [t for t in CLASSIFY if t in tasks]
    used = [models[t] for t in classify]
    if len({(m.bins, m.fps) for m in used}) > 1:
        raise WallcliError("the count and activity models read plots of different bins or frame rates; "
                           "one decode cannot feed both")
    corrections = corrections if corrections is not None else Options()
    with open_video(source, threads=decoder_threads) as reader:
        info = reader.info
        snr = SnrAccumulator(check_roi(None, info.width, info.height), corrections=corrections,
                             fps=float(info.fps)) if "snr" in tasks else None

        check = ViewCheck()
        blend = TemporalNoise()
        from wallcli.snr.column import ColumnSnr

        column = ColumnSnr(fps=float(info.fps))  # the headline figure, as count and activity give it

        def each(frame) -> None:
            check(frame)
            blend(frame)
            column(frame)
            if snr is not None:
                snr.update(frame.planes)
            if on_frame is not None:
                on_frame()

        # repeats (a DVR's padding) are missing samples, interlaced fields one instant and overlays
        # masked for every analysis of this decode
        unique = CameraPipeline(reader, check)
        tee = _Tee(unique, each)
        classifiers = [WindowClassifier(m, int(m.card["stride"]), corrections=corrections,
                                       native_fps=lambda: reader.fps)
                       for m in used]
        if classifiers:
            vertical = any("vertical" in m.input_names for m in used) or corrections.light
            rows = RowStream(tee, bins=used[0].bins, fps=used[0].fps, vertical=vertical, register=corrections.shake)
            for t, row in rows:
                row = stream_row(row, rows)
                for c in classifiers:
                    c.push(t, row, rows.ref)
        else:
            for _ in tee.frames():
                pass
        fps = reader.fps  # as snr reports it
        notes = list(reader.warnings)
    out: dict[str, Any] = {"frames": unique.decoded, "duration": round(unique.last_time + 1.0 / fps, 6), "fps": fps,
                           "warnings": notes, "view": check.summary()}
    for task, c in zip(classify, classifiers):
        out[task] = bound_result(with_view(c.result(source, frames=unique.decoded, fps=fps), check),
                                 blend.correction())
        out[task]["column_snr_db"] = column.db()
    if snr is not None:
        out["snr"] = snr_report(snr, source=source, fps=fps, notes=notes, roi_mode="frame") | {"view": out["view"]}
    for task in TASKS:
        if task in out:
            out[task]["corrections"] += unique.corrections()
    if "snr" in out and unique.repeats.correction():  # as wallcli snr: the file's frames
        out["snr"]["frames"] = unique.decoded
    out["corrections"] = next((out[t]["corrections"] for t in TASKS if t in out), [])
    return out
