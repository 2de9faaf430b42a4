"""Everything a clip's report shows, from one decode of the video.

The frames go once through the space-time rows of ``wallcli count VIDEO``
(:class:`~wallcli.infer.stream.RowStream`), whose windows are classified as they complete, one
:class:`~wallcli.infer.classify.WindowClassifier` per task, exactly as ``wallcli count`` and
``activity`` read a video; on their way they also feed the SNR estimators of ``wallcli snr``
(paper suppl. §3.2) and the view check, and leave their first frame for the picture. The plots
drawn are a bounded copy (:class:`~wallcli.infer.stream.PlotThumbnail`, at most 2048 columns, as
``count --plot``), so memory stays flat in the clip's length (a whole plot was 1.5 KB a frame:
885 MB for 600 s of 720p against 350 MB for 10 s).
"""
from __future__ import annotations

import os
import stat
from dataclasses import dataclass, field
from datetime import datetime, timezone
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable

import numpy as np

from wallcli import __version__
from wallcli.errors import UsageError, WallcliError

TASKS = ("count", "activity")
HEATMAP_CELLS = 48  # cells along the long side, as `wallcli snr --heatmap`
PLOT_COLUMNS = 2048  # time columns of the plots drawn (PlotThumbnail): more than the figure's pixels


@dataclass
class ClipAnalysis:
    source: str
    identity: dict[str, Any]  # the file and the stream, as decoded
    roi: tuple[int, int, int, int]  # of the space-time plots, in source pixels
    plot: Any  # wallcli.signal.stplot.StPlot
    snr: Any  # wallcli.snr.estimate.SnrResult
    grid: Any  # wallcli.snr.map.GridAccumulator
    frame: np.ndarray  # the first decoded frame, RGB float32 0-255
    models: dict[str, Any]  # task -> wallcli.infer.model.Model
    results: dict[str, dict] = field(default_factory=dict)  # task -> docs/contract.md result
    failures: dict[str, str] = field(default_factory=dict)  # task -> why it has no verdict
    warnings: list[str] = field(default_factory=list)
    view: dict[str, Any] = field(default_factory=dict)  # the view check's verdict on the clip
    options: Any = None  # the corrections asked for (wallcli.camera.corrections.Options)
    snr_corrections: list = field(default_factory=list)  # what the SNR estimator's corrections found
    tracks: dict[str, Any] | None = None  # wallcli track's result on the same rows
    column_snr_db: float | None = None  # the headline figure (wallcli.snr.column), as snr --json gives it


class _Tee:
    """A VideoReader as compute_stplot sees it, whose frames also feed the SNR estimators.

    The estimators are set up on the first decoded frame, whose size decides the region (as in
    compute_stplot: a container may announce a wrong size).
    """

    def __init__(self, reader, roi, corrections=None):
        self._reader, self._requested, self._corrections = reader, roi, corrections
        self.info = reader.info
        self.snr = self.grid = self.first = None
        from wallcli.camera.tnr import TemporalNoise
        from wallcli.view.check import ViewCheck

        self.view = ViewCheck(roi)
        self.blend = TemporalNoise()  # a camera's temporal noise reduction (camera/tnr.py)
        from wallcli.camera.pipeline import CameraPipeline

        # repeats, burned-in overlays and interlaced fields taken out as for count and activity
        self.pipeline = CameraPipeline(reader, self.view)

    @property
    def warnings(self) -> list[str]:
        return self._reader.warnings

    def frames(self):
        from wallcli.signal.blocks import check_roi
        from wallcli.snr.estimate import DEFAULT_MAX_PIXELS, SnrAccumulator
        from wallcli.snr.map import GridAccumulator

        self.last = 0.0
        for frame in self.pipeline.frames():
            self.last = frame.time
            planes = frame.planes
            if self.snr is None:
                roi = check_roi(self._requested, planes.width, planes.height)
                self.snr = SnrAccumulator(roi, max_pixels=DEFAULT_MAX_PIXELS, corrections=self._corrections,
                                          fps=float(self.info.fps))
                self.grid = GridAccumulator(roi, HEATMAP_CELLS)
                self.first = planes.rgb()
            self.snr.update(planes)
            self.grid.update(planes)
            self.view(frame)
            self.blend(frame)
            yield frame


def _repeats(corrections: list[dict]) -> int:
    """How many of the decoded frames were repeats left out (the ``duplicates`` correction)."""
    return sum(int(c.get("frames") or 0) for c in corrections if c.get("kind") == "duplicates")


def file_facts(source: str) -> dict[str, Any]:
    """Size, sha256 and modification time of a regular file; None for streams, URLs, devices."""
    from wallcli.infer.card import sha256_file

    if source == "-" or "://" in source:
        return {"size": None, "sha256": None, "modified": None, "absolute": None}
    p = Path(source)
    try:
        st = p.stat()
    except OSError:
        return {"size": None, "sha256": None, "modified": None, "absolute": None}
    if not stat.S_ISREG(st.st_mode):  # a camera or a pipe: reading it to hash it would consume it
        return {"size": None, "sha256": None, "modified": None, "absolute": str(p.resolve())}
    try:
        digest = sha256_file(p)
    except OSError as exc:
        raise WallcliError(f"cannot read {source}: {exc.strerror or exc}") from None
    facts = {"size": st.st_size, "sha256": digest, "absolute": str(p.resolve()), "_stat": (st.st_size, st.st_mtime_ns),
             "modified": datetime.fromtimestamp(st.st_mtime, timezone.utc).isoformat(timespec="seconds")}
    media = playlist_media(p)
    if media is not None:
        facts["media"] = media
    return facts


PLAYLISTS = (".m3u8", ".m3u")
MAX_PLAYLIST_DEPTH = 3  # a master playlist names variant playlists, which name the segments


def playlist_media(path: Path, depth: int = 0, seen: set | None = None) -> list[dict[str, Any]] | None:
    """The files a local HLS playlist names (the video is theirs, not the playlist's text), each
    with its size and sha256, in the playlist's order; None when ``path`` is no playlist. A URL
    it names is listed unhashed; a file that is missing, with its size and sha256 None."""
    from wallcli.infer.card import sha256_file

    if path.suffix.lower() not in PLAYLISTS:
        return None
    seen = set() if seen is None else seen
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError:
        return []
    out: list[dict[str, Any]] = []
    for line in (x.strip() for x in lines):
        if not line or line.startswith("#"):
            continue
        if "://" in line:
            out.append({"path": line, "size": None, "sha256": None})
            continue
        target = (path.parent / line).resolve()
        if target in seen:
            continue
        seen.add(target)
        entry = {"path": str(target), "size": None, "sha256": None}
        try:
            if target.is_file():
                entry.update(size=target.stat().st_size, sha256=sha256_file(target))
        except OSError:
            pass
        out.append(entry)
        if depth < MAX_PLAYLIST_DEPTH and target.suffix.lower() in PLAYLISTS:
            out += playlist_media(target, depth + 1, seen) or []
    return out


def load_models(count_model=None, activity_model=None, threads: int = 0) -> dict[str, Any]:
    """Both models, checked against their cards before any decoding starts."""
    from wallcli.infer.model import load_model

    models = {"count": load_model("count", count_model, threads=threads),
              "activity": load_model("activity", activity_model, threads=threads)}
    if models["count"].bins != models["activity"].bins:
        raise UsageError(f"the count model reads {models['count'].bins} bins and the activity model "
                         f"{models['activity'].bins}; a report draws both from one space-time plot")
    from wallcli.infer.twostage import OnePersonActivity, TwoStageCount

    # count in two stages, as `wallcli count` answers: presence from both nets, then how many;
    # activity checked by the count net for two people, as `wallcli activity` answers
    count_net = models["count"]
    models["count"] = TwoStageCount(count_net, models["activity"])
    models["activity"] = OnePersonActivity(models["activity"], count_net)
    return models


def analyse(source: str, *, roi=None, models: dict[str, Any], threads: int = 0,
            progress: Callable[[int], None] | None = None, corrections=None) -> ClipAnalysis:
    """Decode ``source`` once and measure, plot and classify it (see the module's docstring)."""
    import warnings

    from wallcli.camera.corrections import Options
    from wallcli.camera.tnr import bound_result
    from wallcli.infer.classify import WindowClassifier
    from wallcli.infer.judge import with_view
    from wallcli.infer.stream import PlotThumbnail, RowStream
    from wallcli.infer.windows import stream_row
    from wallcli.io.video import open_video

    if str(source).lower().endswith(".npz"):
        raise WallcliError(f"{source} is a space-time plot; a report needs the video itself (its frame, SNR and identity)")
    if len({float(m.fps) for m in models.values()}) > 1:
        raise UsageError("the count and activity models read plots at different frame rates; a report reads one")
    options = corrections if corrections is not None else Options()
    facts = file_facts(source)
    thumb = PlotThumbnail(PLOT_COLUMNS)
    from wallcli.signal.track import TrackBuilder

    with warnings.catch_warnings(record=True) as caught, open_video(source, threads=threads) as reader:
        warnings.simplefilter("always")
        info = reader.info
        tee = _Tee(reader, roi, corrections)
        classifiers = {t: WindowClassifier(m, int(m.card["stride"]), corrections=options,
                                          native_fps=lambda: reader.fps)
                       for t, m in models.items() if t in TASKS}
        first = models["count"]
        rows = RowStream(tee, roi=roi, bins=first.bins, fps=first.fps, progress=progress, vertical=True,
                         register=options.shake)
        tracker = TrackBuilder(first.fps, gaps=lambda: reader.gaps)  # no track across frames lost, as track's
        for t, row in rows:
            thumb.push(t, row)
            tracker.push(t, row[:first.bins])
            row = stream_row(row, rows)
            for c in classifiers.values():
                c.push(t, row, rows.ref)
    if rows.frames < 2:
        raise WallcliError(f"{source} has {rows.frames} frame(s); a space-time plot needs at least 2 "
                           "(the temporal mean of one frame is the frame itself)")
    plot = thumb.plot(rows, first.bins, first.fps)
    rate = info.fps if reader.fps == float(info.fps) else Fraction(reader.fps).limit_denominator(1001)
    plot.meta.update(frame_size=list(rows.frame_size), fps_fraction=f"{rate.numerator}/{rate.denominator}")
    notes = list(dict.fromkeys([str(w.message) for w in caught] + list(reader.warnings)))
    if tee.snr is not None:
        tee.snr.finish()  # frames still waiting for their corrections' gains
    if tee.snr.frames < 3:
        raise WallcliError(f"{source}: only {tee.snr.frames} frame(s) decoded; the noise estimate needs at least 3")
    snr = tee.snr.result()
    notes += snr.warnings
    before = facts.pop("_stat", None)
    if before is not None:
        try:
            st = os.stat(source)
            if (st.st_size, st.st_mtime_ns) != before:
                notes.append(f"{source} changed while it was analysed; its size and sha256 are those from before")
        except OSError:
            notes.append(f"{source} disappeared while it was analysed")
    fps = reader.fps  # as snr and stplot report it
    identity = {
        "path": str(source), **facts,
        "container": info.container, "codec": info.codec, "pix_fmt": info.pix_fmt,
        "width": plot.meta["frame_size"][0], "height": plot.meta["frame_size"][1],
        "fps": fps, "fps_fraction": plot.meta.get("fps_fraction"),
        "declared_frames": info.frame_count, "declared_duration": info.duration,
        # the frames decoded, repeats included (as snr, stplot and scan count them); the repeats left
        # out of the analysis are the duplicates correction, said beside this count too
        "frames": tee.pipeline.decoded, "repeats": _repeats(tee.pipeline.corrections()),
        "duration": float(tee.last) + 1.0 / fps,
        "warnings": notes,
        "wallcli_version": __version__,
        "generated": datetime.now(timezone.utc).isoformat(timespec="seconds"),
    }
    from wallcli.camera.corrections import Options

    out = ClipAnalysis(str(source), identity, tuple(rows.roi), plot, snr, tee.grid, tee.first, models,
                       warnings=notes, view=tee.view.summary(),
                       options=corrections if corrections is not None else Options(),
                       snr_corrections=list(tee.snr.corrections),
                       # the accumulator's own column tap: the same frames, the figure snr --json gives
                       column_snr_db=tee.snr.column.db() if getattr(tee.snr, "column", None) is not None else None)
    from wallcli.infer.track import MIN_SAMPLES, track_result

    if tracker.samples >= MIN_SAMPLES:
        out.tracks = track_result(str(source), tracker.finish(), fps=float(fps))  # the video's rate
    for task, c in classifiers.items():
        try:
            result = c.result(str(source), frames=tee.pipeline.decoded, fps=fps)
            out.results[task] = bound_result(with_view(result, tee.view),
                                             tee.blend.correction())
            out.results[task]["corrections"] += tee.pipeline.corrections()
        except WallcliError as exc:  # too short for one window: the rest of the report still stands
            out.failures[task] = str(exc)
    return out
