"""The report's pictures: the figures of the other commands (wallcli.plots), embedded as data: URIs.

The plotting functions write PNG files (atomically); they are drawn into a private temporary
folder and read back, so the report uses the very figures `snr --heatmap`, `stplot --png` and
`count --plot` draw.
"""
from __future__ import annotations

import base64
import dataclasses
import tempfile
from pathlib import Path


def data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def figure_label(source: str) -> str:
    """The file's name as matplotlib titles show it: '$' would start mathematical text."""
    name = Path(source).name or source
    return name.replace("$", r"\$")


def clip_figures(a) -> dict[str, str]:
    """{name: data URI} for a :class:`wallcli.report.analysis.ClipAnalysis`."""
    from wallcli.plots.frame import save_frame_png
    from wallcli.plots.snr import save_heatmap_png
    from wallcli.plots.stplot import save_stplot_png
    from wallcli.plots.timeline import save_timeline_png

    label = figure_label(a.source)
    plot = dataclasses.replace(a.plot, meta=dict(a.plot.meta, source=label))
    out: dict[str, str] = {}
    with tempfile.TemporaryDirectory(prefix="wallcli-report-") as tmp:
        def draw(name, fn, *args, **kwargs):
            path = Path(tmp) / f"{name}.png"
            fn(path, *args, **kwargs)
            out[name] = data_uri(path.read_bytes())

        draw("frame", save_frame_png, a.frame, a.roi, title=f"{label}: first decoded frame")
        draw("heatmap", save_heatmap_png, a.grid, of="snr", title=label)
        draw("stplot", save_stplot_png, plot)
        if a.tracks is not None:
            from wallcli.plots.track import save_track_png

            draw("tracks", save_track_png, plot, dict(a.tracks, input=label))
        for task, result in a.results.items():
            draw(f"timeline_{task}", save_timeline_png, dict(result, input=label), plot)
    return out
