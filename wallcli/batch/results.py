"""The results file of ``wallcli scan``: JSON Lines (or CSV), appended line by line.

The file is the run's only memory, and one run at a time writes it: a scan holds an advisory
lock (``flock``) on it from before it reads it until it ends, and a second scan of the same file
stops at once, saying so (two writers would both append every video). Every finished video's line is written, flushed and fsynced
before the next one is, so a crash, Ctrl-C or ``kill -9`` leaves every finished line intact and
at most one torn last line, which the next run drops. On that next run, lines of videos that are
unchanged (same sha256), scanned for the same tasks, with the same options (each line records them
under "options") and the same models are kept and their videos skipped; errors, videos that
changed and lines made with other options or models are done again and their old lines dropped,
so each video keeps exactly one line. Writing it is resultsfile.py's part; what a line may hold,
validate.py's.
"""
from __future__ import annotations

import csv
import io
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from wallcli.errors import WallcliError
from wallcli.io import jsonfile
from wallcli.io.text import escape_surrogates, unescape_surrogates

BASE = ["input", "size", "sha256", "duration", "frames", "tasks", "options", "seconds", "error", "warnings"]
CHANNELS = ("r", "g", "b")


def is_csv(path: str | os.PathLike) -> bool:
    return str(path).lower().endswith(".csv")


def key(source: str) -> str:
    """Which video a line is about: its input as written, normalised (./a.mp4 == a.mp4)."""
    return source if "://" in source else os.path.normpath(source)


# ------------------------------------------------------------------------------------------ CSV
def csv_columns(tasks, classes: dict[str, list], windows: bool = False) -> list[str]:
    """The CSV header: fixed by the tasks and the models' classes, so rows of any video line up."""
    cols = list(BASE)
    for task in ("count", "activity"):
        if task in tasks:
            cols += [f"{task}.label", f"{task}.confident", f"{task}.reason"]
            cols += [f"{task}.signal_db"]  # what the answer was judged on; the JSON line has it too
            cols += [f"{task}.probabilities.{c}" for c in classes[task]]
            cols += [f"{task}.model.name", f"{task}.model.version", f"{task}.model.sha256"]
            cols += [f"{task}.windows"] if windows else []
    if "snr" in tasks:
        cols += ["snr.roi", "snr.frames"]
        cols += [f"snr.{q}.{c}" for q in ("signal_power", "noise_power", "snr_db") for c in CHANNELS]
        cols += ["snr.sampled_pixels", "snr.exact", "snr.scales"]
        # the line the terminal leads with: a CSV reader should not have to re-derive it from scales
        cols += [f"snr.verdict.{k}" for k in ("signal", "block", "snr_db", "text")]
    # the view check's verdict, whatever the tasks (it rides on every decode); its notes (a sharp
    # shadow in view) do not make it unusable but say what the answers were read through
    return cols + ["view.usable", "view.issues", "view.reason", "view.notes"]


# a spreadsheet runs a cell that begins with one of these as a formula (=1+2, @SUM(A1), -2+3; a
# tab or CR before them is skipped): OWASP's "CSV injection" advice is a leading quote, which
# makes the cell text. A text cell that begins with a quote gets one too, so that reading back
# (a resume) strips exactly one: every name survives the round trip
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r", "'")


def defuse(text: str) -> str:
    """A text cell that no spreadsheet takes for a formula; :func:`undefuse` gives ``text`` back."""
    return "'" + text if text.startswith(FORMULA_STARTS) else text


def undefuse(cell: str) -> str:
    return cell[1:] if cell.startswith("'") else cell


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return str(value)  # a number stays a number: -3.5 is no formula, and no quote is put before it
    if isinstance(value, str):
        return defuse(value)  # file names, reasons, errors: anyone's text
    return json.dumps(value, ensure_ascii=False)  # lists of objects (windows, scales), warnings


def csv_record(cells: list[str]) -> str:
    """One CSV record, newline included, that ``csv.reader`` reads back as ``cells`` whatever they
    hold: newlines and quotes inside a cell are quoted (a file name may hold them), and a file
    name's undecodable bytes are escaped as in JSON (a CSV is UTF-8 text)."""
    buf = io.StringIO()
    # csv.writer quotes a cell holding the line terminator's characters, but not a bare '\r',
    # which readers take for a line end: a row holding one is quoted whole
    quoting = csv.QUOTE_ALL if any("\r" in c for c in cells) else csv.QUOTE_MINIMAL
    csv.writer(buf, lineterminator="\n", quoting=quoting).writerow(cells)
    return escape_surrogates(buf.getvalue())


def flatten(line: dict, columns: list[str]) -> list[str]:
    """One CSV row: nested objects joined with '.', lists named by the classes or channels beside
    them; whatever is not a column (the full objects' other fields) is left to the JSON format."""
    flat: dict[str, Any] = {k: line.get(k) for k in BASE}
    flat["tasks"] = ",".join(line.get("tasks") or [])
    if isinstance(line.get("view"), dict):
        flat.update({f"view.{k}": v for k, v in line["view"].items()})
    for task in ("count", "activity", "snr"):
        obj = line.get(task)
        if not isinstance(obj, dict):
            continue
        names = obj.get("classes") if task != "snr" else obj.get("channels")
        for k, v in obj.items():
            if isinstance(v, dict):
                flat.update({f"{task}.{k}.{kk}": vv for kk, vv in v.items()})
            elif isinstance(v, list) and names and len(v) == len(names) and k != "roi" \
                    and all(isinstance(x, (int, float)) for x in v):
                flat.update({f"{task}.{k}.{n}": x for n, x in zip(names, v)})
            elif k == "roi" and isinstance(v, list):
                flat[f"{task}.roi"] = ",".join(str(x) for x in v)
            else:
                flat[f"{task}.{k}"] = v
    return [_cell(flat.get(c)) for c in columns]


# ------------------------------------------------------------------------------------- reading
@dataclass
class Entry:
    raw: str  # the line as stored, newline excluded: kept lines are written back byte for byte
    input: str
    size: int | None
    sha256: str | None
    tasks: tuple[str, ...]
    error: str | None
    options: dict | None = None  # the options that made it (ScanConfig.options); None: not recorded
    models: dict | None = None  # task -> sha256 of the model that answered it
    view: dict | None = None  # the clip's view verdict (--strict reads it on a resume)


def _models(d: dict) -> dict:
    return {t: (d.get(t) or {}).get("model", {}).get("sha256") for t in ("count", "activity")
            if isinstance(d.get(t), dict) and isinstance(d[t].get("model"), dict)}


def _entry_json(raw: str) -> Entry | str:
    """The entry of one stored line, or why it cannot be a line of scan's (the validator
    ``wallcli report`` runs too)."""
    from wallcli.batch.validate import line_problem

    try:
        d = jsonfile.loads(raw, allow_nan=True)
    except json.JSONDecodeError as exc:
        return f"not JSON ({exc.msg})"
    why = line_problem(d)
    if why is None and not isinstance(d.get("tasks"), list):
        why = 'no "tasks" list'  # every line scan ever resumed records its tasks
    if why is not None:
        return why
    options = d.get("options") if isinstance(d.get("options"), dict) else None
    view = d.get("view") if isinstance(d.get("view"), dict) else None
    return Entry(raw, d["input"], d.get("size"), d.get("sha256"), tuple(d["tasks"]), d.get("error"), options,
                 _models(d), view)


def _entry_csv(row: list[str], header: list[str]) -> Entry | None:
    if len(row) != len(header):
        return None
    d = dict(zip(header, row))
    try:
        size = int(d["size"]) if d["size"] else None
    except ValueError:
        return None
    try:
        options = jsonfile.loads(d["options"], allow_nan=True) if d.get("options") else None
    except json.JSONDecodeError:
        options = None
    models = {t: d[f"{t}.model.sha256"] for t in ("count", "activity") if d.get(f"{t}.model.sha256")}
    view = None
    if d.get("view.usable"):
        view = {"usable": d["view.usable"] == "true", "reason": undefuse(d.get("view.reason") or "") or None}
    return Entry(csv_record(row)[:-1], unescape_surrogates(undefuse(d["input"])), size, d["sha256"] or None,
                 tuple(t for t in d["tasks"].split(",") if t), undefuse(d["error"]) or None,
                 options if isinstance(options, dict) else None, models, view)


def _not_ours(path: Path, n: int, why: str | None = None) -> WallcliError:
    return WallcliError(f"{path} line {n} is not a wallcli scan result" + (f": {why}" if why else ""),
                        hint="choose another -o, or --force to replace the file")


def _read_csv(path: Path, text: str, columns: list[str]) -> tuple[list[Entry], bool]:
    """Records by the csv module's rules (a quoted cell may hold newlines), as they were written."""
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    rows: list[tuple[int, list[str]]] = []
    torn = False
    try:
        for row in reader:
            rows.append((reader.line_num, row))
    except csv.Error as exc:
        if "unexpected end of data" not in str(exc):
            raise _not_ours(path, reader.line_num) from None
        torn = True  # the file ends inside a quoted cell: the last record was cut short
    else:
        if rows and not text.endswith("\n"):
            rows.pop()  # a record is whole once its newline is written
            torn = True
    if rows:
        if rows[0][1] != columns:
            raise WallcliError(f"{path} has other columns than this scan writes (another --task or --windows, or "
                               "an older wallcli?)",
                               hint="use the same options, another -o, or --force to start it again")
        rows = rows[1:]
    entries = []
    for n, row in rows:
        if not row:
            continue
        e = _entry_csv(row, columns)
        if e is None:
            raise _not_ours(path, n)
        entries.append(e)
    return entries, torn


def read(path: Path, columns: list[str] | None) -> tuple[list[Entry], bool]:
    """(entries, torn): the lines of an earlier run; ``torn`` when its last line was cut short.

    Anything else that is not a line of ours means the file is not a scan's results: refusing to
    append to it (or to rewrite it) keeps someone's other file safe.
    """
    data = path.read_bytes()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise WallcliError(f"{path} is not a wallcli scan results file (not UTF-8 text)",
                           hint="choose another -o, or --force to replace it") from None
    if columns is not None:
        return _read_csv(path, text, columns)
    torn = bool(text) and not text.endswith("\n")
    lines = text.split("\n")[:-1]  # the text after the last newline: '' or the torn line
    entries = []
    for n, raw in enumerate(lines, start=1):
        if not raw.strip():
            continue
        e = _entry_json(raw)
        if isinstance(e, str):
            raise _not_ours(path, n, e)
        entries.append(e)
    return entries, torn
