"""Everything a clip's report shows, from one decode of the video.

The frames go once through :func:`wallcli.signal.stplot.compute_stplot`; on their way they also
feed the SNR estimators of ``wallcli snr`` (paper suppl. §3.2) and leave their first frame for the
picture. count and activity then read the finished plot exactly as ``wallcli count plots.npz``
does (``classify_plot``), so no second decode is needed. Memory is that of ``wallcli stplot``:
the two plots, 1.5 KB per frame at 64 bins; frames themselves are streamed.
"""
from __future__ import annotations

import os
import stat
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Callable

import numpy as np

from wallcli import __version__
from wallcli.errors import UsageError, WallcliError

TASKS = ("count", "activity")
HEATMAP_CELLS = 48  # cells along the long side, as `wallcli snr --heatmap`


@dataclass
class ClipAnalysis:
    source: str
    identity: dict[str, Any]  # the file and the stream, as decoded
    roi: tuple[int, int, int, int]  # of the space-time plots, in source pixels
    plot: Any  # wallcli.signal.stplot.StPlot
    snr: Any  # wallcli.signal.snr.SnrResult
    grid: Any  # wallcli.signal.snr.GridAccumulator
    frame: np.ndarray  # the first decoded frame, RGB float32 0-255
    models: dict[str, Any]  # task -> wallcli.infer.model.Model
    results: dict[str, dict] = field(default_factory=dict)  # task -> docs/contract.md result
    failures: dict[str, str] = field(default_factory=dict)  # task -> why it has no verdict
    warnings: list[str] = field(default_factory=list)
    view: dict[str, Any] = field(default_factory=dict)  # the view check's verdict on the clip
    options: Any = None  # the corrections asked for (wallcli.signal.corrections.Options)
    snr_corrections: list = field(default_factory=list)  # what the SNR estimator's corrections found


class _Tee:
    """A VideoReader as compute_stplot sees it, whose frames also feed the SNR estimators.

    The estimators are set up on the first decoded frame, whose size decides the region (as in
    compute_stplot: a container may announce a wrong size).
    """

    def __init__(self, reader, roi, corrections=None):
        self._reader, self._requested, self._corrections = reader, roi, corrections
        self.info = reader.info
        self.snr = self.grid = self.first = None
        from wallcli.signal.view import ViewCheck

        self.view = ViewCheck(roi)

    @property
    def warnings(self) -> list[str]:
        return self._reader.warnings

    def frames(self):
        from wallcli.signal.blocks import check_roi
        from wallcli.signal.snr import DEFAULT_MAX_PIXELS, GridAccumulator, SnrAccumulator

        for frame in self._reader.frames():
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
            yield frame


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
    return {"size": st.st_size, "sha256": digest, "absolute": str(p.resolve()), "_stat": (st.st_size, st.st_mtime_ns),
            "modified": datetime.fromtimestamp(st.st_mtime, timezone.utc).isoformat(timespec="seconds")}


def load_models(count_model=None, activity_model=None, threads: int = 0) -> dict[str, Any]:
    """Both models, checked against their cards before any decoding starts."""
    from wallcli.infer.model import load_model

    models = {"count": load_model("count", count_model, threads=threads),
              "activity": load_model("activity", activity_model, threads=threads)}
    if models["count"].bins != models["activity"].bins:
        raise UsageError(f"the count model reads {models['count'].bins} bins and the activity model "
                         f"{models['activity'].bins}; a report draws both from one space-time plot")
    return models


def analyse(source: str, *, roi=None, models: dict[str, Any], threads: int = 0,
            progress: Callable[[int], None] | None = None, corrections=None) -> ClipAnalysis:
    """Decode ``source`` once and measure, plot and classify it (see the module's docstring)."""
    import warnings

    from wallcli.infer.classify import classify_plot, with_view
    from wallcli.io.video import open_video
    from wallcli.signal.stplot import compute_stplot

    if str(source).lower().endswith(".npz"):
        raise WallcliError(f"{source} is a space-time plot; a report needs the video itself (its frame, SNR and identity)")
    facts = file_facts(source)
    with warnings.catch_warnings(record=True) as caught, open_video(source, threads=threads) as reader:
        warnings.simplefilter("always")
        tee = _Tee(reader, roi, corrections)
        plot = compute_stplot(tee, roi=roi, bins=models["count"].bins, mean="clip", progress=progress)
        info = reader.info
    notes = list(dict.fromkeys([str(w.message) for w in caught] + list(plot.meta.get("warnings", []))))
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
    t = plot.time
    fps = float(info.fps)
    identity = {
        "path": str(source), **facts,
        "container": info.container, "codec": info.codec, "pix_fmt": info.pix_fmt,
        "width": plot.meta["frame_size"][0], "height": plot.meta["frame_size"][1],
        "fps": fps, "fps_fraction": plot.meta.get("fps_fraction"),
        "declared_frames": info.frame_count, "declared_duration": info.duration,
        "frames": plot.frames, "duration": float(t[-1] - t[0]) + 1.0 / fps,
        "warnings": notes,
        "wallcli_version": __version__,
        "generated": datetime.now(timezone.utc).isoformat(timespec="seconds"),
    }
    from wallcli.signal.corrections import Options

    out = ClipAnalysis(str(source), identity, tuple(plot.meta["roi"]), plot, snr, tee.grid, tee.first, models,
                       warnings=notes, view=tee.view.summary(),
                       options=corrections if corrections is not None else Options(),
                       snr_corrections=list(tee.snr.corrections))
    for task in TASKS:
        model = models[task]
        try:
            out.results[task] = with_view(classify_plot(model, plot, stride=int(model.card["stride"]), source=str(source),
                                                        **({"corrections": corrections} if corrections is not None else {})),
                                          tee.view)
        except WallcliError as exc:  # too short for one window: the rest of the report still stands
            out.failures[task] = str(exc)
    return out
