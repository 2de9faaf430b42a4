"""The two pages: one clip (:func:`clip_page`) and a scan's many videos (:func:`scan_page`)."""
from __future__ import annotations

from datetime import datetime, timezone
from typing import Any

from wallcli.report.render import render
from wallcli.report.verdicts import answer, container_name, finding

CHANNELS = ("R", "G", "B")


def _snr_rows(snr) -> list[dict[str, Any]]:
    return [{"block": s.block, "blocks": s.blocks, "signal": [float(x) for x in s.signal_power],
             "noise": [float(x) for x in s.noise_power], "snr_db": [float(x) for x in s.snr_db]}
            for s in snr.scales]


def _task_view(task: str, result: dict | None, failure: str | None, figure: str | None) -> dict[str, Any]:
    if result is None:
        return {"task": task, "result": None, "failure": failure or "no result", "figure": None, "windows": [],
                "classes": [], "clip": answer(task, None), "model": None,
                "finding": f"{task.capitalize()}: no answer ({failure or 'no result'})"}
    classes = [str(c) for c in result.get("classes", [])]
    windows = []
    for w in result.get("windows", []):
        windows.append({"start": w.get("start"), "end": w.get("end"), "answer": answer(task, w),
                        "signal_db": w.get("signal_db"), "probabilities": list(w.get("probabilities") or [])})
    return {"task": task, "result": result, "failure": None, "figure": figure, "windows": windows,
            "classes": classes, "clip": answer(task, result), "probabilities": list(result.get("probabilities") or []),
            "undetermined": sum(not w["answer"]["decided"] for w in windows), "finding": finding(task, result)}


def _correction_text(c: dict) -> str:
    """One correction as a line of text: its kind and what was found (lists summarised)."""
    parts = []
    for k, v in c.items():
        if k == "kind":
            continue
        if isinstance(v, list):
            v = f"{len(v)}"
        elif isinstance(v, float):
            v = f"{v:.4g}"
        parts.append(f"{k.replace('_', ' ')} {v}")
    return str(c.get("kind", "?")) + (f" ({', '.join(parts)})" if parts else "")


def corrections_view(a) -> dict[str, Any]:
    """What the page says of the corrections: those asked for and off, and per analysis what was
    found and removed before it (the JSON's ``corrections``)."""
    opts = a.options
    off = [flag for flag, on in (("--no-deflicker", getattr(opts, "deflicker", True)),
                                 ("--no-exposure", getattr(opts, "exposure", True)),
                                 ("--no-shake", getattr(opts, "shake", True))) if not on]
    found = []
    for where, items in (("count", (a.results.get("count") or {}).get("corrections")),
                         ("activity", (a.results.get("activity") or {}).get("corrections")),
                         ("signal and noise", a.snr_corrections)):
        if items is not None:
            found.append({"where": where, "items": [_correction_text(c) for c in items]})
    return {"off": off, "found": found}


def clip_page(a, *, command: str) -> str:
    """The HTML report of a :class:`wallcli.report.analysis.ClipAnalysis`."""
    from wallcli.report.cards import model_summary
    from wallcli.report.figures import clip_figures

    from wallcli.snr.verdict import snr_verdict
    from wallcli.wording import VIEW_NOTE

    figures = clip_figures(a)
    rows = _snr_rows(a.snr)
    tasks = [_task_view(t, a.results.get(t), a.failures.get(t), figures.get(f"timeline_{t}"))
             for t in ("count", "activity")]
    return render(
        "clip.html.j2",
        title=a.identity["path"], command=command, roi=list(a.roi), view_note=VIEW_NOTE,
        identity=dict(a.identity, container=container_name(a.identity.get("container"), a.identity.get("path"))),
        # the verdict `wallcli snr` leads with, on the page's own figures (its ROI, these rows)
        snr={"rows": rows, "roi": list(a.snr.roi), "frames": a.identity["frames"],
             "repeats": a.identity.get("repeats", 0), "exact": a.snr.exact,
             "pixels": a.snr.sampled_pixels, "channels": CHANNELS, "verdict": snr_verdict({"scales": rows})},
        grid={"rows": a.grid.rows, "cols": a.grid.cols, "cw": a.grid.cw, "ch": a.grid.ch},
        plot={"bins": a.plot.bins, "frames": a.identity["frames"]},
        figures=figures, tasks=tasks, models=[model_summary(a.models[t]) for t in ("count", "activity")],
        corrections=corrections_view(a), view=a.view, tracks=a.tracks, column=_column_view(a),
    )


def _column_view(a) -> dict[str, Any]:
    """The headline figure as every command prints it first (wallcli.snr.column.column_text)."""
    from wallcli.snr.column import NAME, column_text

    db = getattr(a, "column_snr_db", None)
    return {"name": NAME, "db": db, "text": column_text(db)}


def scan_page(source: str, summary: dict[str, Any], problems: list[str], *, command: str) -> str:
    return render(
        "index.html.j2", scripts=("table.js",),
        title=source, source=source, rows=summary["rows"], totals=summary["totals"], problems=problems,
        command=command,
        generated=datetime.now(timezone.utc).isoformat(timespec="seconds"),
    )
