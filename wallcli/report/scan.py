"""The summary of a ``wallcli scan`` run: its JSON Lines (docs/contract.md), one row per video.

A scan writes and flushes one line per video as it finishes, so a killed scan leaves a file
whose last line may be cut short; a line that is not a JSON object becomes a row carrying that
error instead of stopping the summary. A line that is an object but holds what scan never writes
(a negative duration, NaN probabilities, a task's answer replaced by null) is refused, as a
resume of that file refuses it: the page would show it as an answer.
"""
from __future__ import annotations

import json
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from wallcli.batch.validate import line_problem
from wallcli.errors import WallcliError
from wallcli.io import jsonfile
from wallcli.report.verdicts import answer

TASKS = ("count", "activity")
_STAND_IN = "_wallcli_stand_in"  # marks the record made for a line that is not one
_COPY_OF = "_wallcli_copy_of"  # the input of the first line with the same sha256


def _num(x) -> float | None:
    return float(x) if isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) else None


def read_results(path: str | Path) -> tuple[list[dict[str, Any]], list[str]]:
    """(records, problems): every non-blank line, a dict or a stand-in carrying its error."""
    try:
        text = Path(path).read_text(encoding="utf-8", errors="replace")
    except FileNotFoundError:
        raise WallcliError(f"no such file: {path}") from None
    except IsADirectoryError:
        raise WallcliError(f"{path} is a folder, not a results file") from None
    except OSError as exc:
        raise WallcliError(f"cannot read {path}: {exc.strerror or exc}") from None
    records, problems = [], []
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        try:
            rec = jsonfile.loads(line, allow_nan=True)
        except json.JSONDecodeError as exc:
            rec = None
            why = f"line {n} is not JSON ({exc.msg}); a scan stopped while writing it?"
        else:
            why = f"line {n} is not a JSON object"
        if not isinstance(rec, dict):
            problems.append(f"{path}: {why}")
            rec = {"input": f"(line {n})", "error": why, _STAND_IN: True}
        else:
            impossible = line_problem(rec)
            if impossible:
                raise WallcliError(f"{path} line {n} is not a wallcli scan result: {impossible}",
                                   hint="report reads the lines 'wallcli scan' writes")
        records.append(rec)
    if not records:
        raise WallcliError(f"{path} holds no results (expected one JSON object per line, as 'wallcli scan' writes)")
    return _once_each(records, path, problems), problems


def _once_each(records: list[dict[str, Any]], path, problems: list[str]) -> list[dict[str, Any]]:
    """One record per video: the last line of each input counts. A scan replaces a video's line
    when it redoes it, so a second line comes from two scans that appended at once (before scan
    locked its file) or from results files put together; the later line is the newer."""
    from wallcli.batch.results import key

    keys = [key(r["input"]) if isinstance(r.get("input"), str) and not r.get(_STAND_IN) else None for r in records]
    last = {k: i for i, k in enumerate(keys) if k is not None}
    kept = [r for i, (r, k) in enumerate(zip(records, keys)) if k is None or last[k] == i]
    repeated = len({k for i, k in enumerate(keys) if k is not None and last[k] != i})
    if repeated:
        problems.append(f"{path}: {repeated} video{'s' if repeated != 1 else ''} appear on more than one line; "
                        "the last line of each is counted")
    # one recording under two names (a hard link, a copy): each file scanned is a row, the later
    # ones marked as copies of the first (merging them hid files: 4 copies of 6 clips read 7 videos)
    first: dict[str, str] = {}
    copies = 0
    for r in kept:
        sha = r.get("sha256") if isinstance(r.get("sha256"), str) and not r.get(_STAND_IN) else None
        if sha:
            if sha in first:
                r[_COPY_OF] = first[sha]
                copies += 1
            else:
                first[sha] = str(r.get("input"))
    if copies:
        problems.append(f"{path}: {copies} of the videos {'are copies' if copies != 1 else 'is a copy'} of another "
                        "(the same sha256): each is a row, marked as a copy")
    return kept


def snr_figure(snr: Any) -> float | None:
    """The video's pixel SNR on the green channel: ``snr.snr_db[1]`` of its results line, as it is
    there (a figure computed here, as the RGB mean once was, matched no number in the results)."""
    if not isinstance(snr, dict):
        return None
    db, channels = snr.get("snr_db"), snr.get("channels")
    if not isinstance(db, list) or not db:
        return None
    g = channels.index("g") if isinstance(channels, list) and "g" in channels else min(1, len(db) - 1)
    return _num(db[g]) if g < len(db) else None


def column_figure(rec: dict[str, Any]) -> float | None:
    """The headline column SNR (``column_snr_db``, wallcli/snr/column.py) of a results line: its
    snr object's, else count's, else activity's (one decode measures it once; scan copies it)."""
    for task in ("snr", *TASKS):
        obj = rec.get(task)
        if isinstance(obj, dict) and _num(obj.get("column_snr_db")) is not None:
            return _num(obj["column_snr_db"])
    return None


def _signal(obj: Any) -> float | None:
    """A task's signal_db: the analysed windows' signal over the plot's noise, its answer judged on it."""
    return _num(obj.get("signal_db")) if isinstance(obj, dict) else None


def _row(rec: dict[str, Any]) -> dict[str, Any]:
    error = rec.get("error")
    error = None if error is None else " ".join(str(error).split())
    tasks = {t: answer(t, rec.get(t)) if isinstance(rec.get(t), dict) else None for t in TASKS}
    flags = [a["confident"] for a in tasks.values() if a is not None]
    confident = False if False in flags else (True if flags and all(f is True for f in flags) else None)
    size = rec.get("size")
    return {
        "name": str(rec.get("input")) if rec.get("input") is not None else "(no input named)",
        "duration": _num(rec.get("duration")), "frames": _num(rec.get("frames")),
        "size": size if isinstance(size, int) and not isinstance(size, bool) else None,
        "sha256": rec.get("sha256") if isinstance(rec.get("sha256"), str) else None,
        "column_snr_db": column_figure(rec),
        "snr_db": snr_figure(rec.get("snr")),
        "signal_db": {t: _signal(rec.get(t)) for t in TASKS},
        "count": tasks["count"], "activity": tasks["activity"],
        "confident": confident, "error": error, "copy_of": rec.get(_COPY_OF),
    }


def summarise(records: list[dict[str, Any]]) -> dict[str, Any]:
    rows = [_row(r) for r in records]
    ok = [r for r in rows if r["error"] is None]

    def tally(task):
        c = Counter("undetermined" if not r[task]["decided"] else r[task]["label"] for r in ok if r[task] is not None)
        return sorted(c.items(), key=lambda kv: (kv[0] == "undetermined", kv[0]))

    return {
        "rows": rows,
        "totals": {
            "videos": len(rows), "ok": len(ok), "failed": len(rows) - len(ok),
            "copies": sum(r["copy_of"] is not None for r in rows),
            "duration": sum(r["duration"] or 0.0 for r in ok),
            "frames": int(sum(r["frames"] or 0 for r in ok)),
            "size": sum(r["size"] or 0 for r in rows),
            # per task: activity may be decided on videos whose count is not (one figure for both,
            # 'decided 0 / undetermined 9', hid activity's 6 decided answers)
            "answered": {t: sum(r[t] is not None for r in ok) for t in TASKS},
            "decided": {t: sum(r[t] is not None and r[t]["decided"] for r in ok) for t in TASKS},
            "count": tally("count"), "activity": tally("activity"),
        },
    }
