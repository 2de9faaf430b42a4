"""The results file of ``wallcli scan``: JSON Lines (or CSV), appended line by line.

The file is the run's only memory, and one run at a time writes it: a scan holds an advisory
lock (``flock``) on it from before it reads it until it ends, and a second scan of the same file
stops at once, saying so (two writers would both append every video). Every finished video's line is written, flushed and fsynced
before the next one is, so a crash, Ctrl-C or ``kill -9`` leaves every finished line intact and
at most one torn last line, which the next run drops. On that next run, lines of videos that are
unchanged (same sha256), scanned for the same tasks, with the same options (each line records them
under "options") and the same models are kept and their videos skipped; errors, videos that
changed and lines made with other options or models are done again and their old lines dropped,
so each video keeps exactly one line. Rewriting the file (--force, or dropping such lines) waits
for the run's first new line: a run that ends before one leaves the file as it was.
"""
from __future__ import annotations

import csv
import errno
import io
import json
import os
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

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


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float, str)):
        return str(value)
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


def _entry_json(raw: str) -> Entry | None:
    try:
        d = jsonfile.loads(raw, allow_nan=True)
    except json.JSONDecodeError:
        return None
    if not isinstance(d, dict) or not isinstance(d.get("input"), str) or not isinstance(d.get("tasks"), list):
        return None
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
        view = {"usable": d["view.usable"] == "true", "reason": d.get("view.reason") or None}
    return Entry(csv_record(row)[:-1], unescape_surrogates(d["input"]), size, d["sha256"] or None,
                 tuple(t for t in d["tasks"].split(",") if t), d["error"] or None,
                 options if isinstance(options, dict) else None, models, view)


def _not_ours(path: Path, n: int) -> WallcliError:
    return WallcliError(f"{path} line {n} is not a wallcli scan result",
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
        if e is None:
            raise _not_ours(path, n)
        entries.append(e)
    return entries, torn


# ------------------------------------------------------------------------------------- writing
class ResultsFile:
    """The results file of one run: :meth:`open` (and lock) it before reading it, :meth:`start`
    appending, :meth:`append` a line per video, :meth:`close` (or :meth:`abandon`) at the end."""

    def __init__(self, path: Path, encode: Callable[[dict], str], columns: list[str] | None = None):
        self.path, self.encode, self.columns = Path(path), encode, columns
        self.created = False  # by this run: removed again if the run fails before its first line
        self.appended = 0
        self._fd: int | None = None
        self._fh = None
        self._pending: list[Entry] | None = None  # lines the file is to be replaced by (start)

    def open(self) -> None:
        """Open the file, creating it if absent, and take its lock; a scan already holding it is
        an error, at once (a batch that waited would only redo that scan's work)."""
        flags = os.O_RDWR | os.O_APPEND | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
        for _ in range(20):
            try:
                try:
                    fd = os.open(self.path, flags | os.O_CREAT | os.O_EXCL, 0o666)
                    created = True
                except FileExistsError:
                    fd = os.open(self.path, flags)  # O_NONBLOCK: a FIFO put there meanwhile must not hang us
                    created = False
            except FileNotFoundError:
                continue  # removed between the two opens: try again
            except OSError as exc:
                raise WallcliError(f"cannot open {self.path}: {_reason(exc)}") from None
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                os.close(fd)
                raise WallcliError(f"{self.path} is not a regular file; scan results go to a file")
            try:
                _lock(fd, self.path)
            except BaseException:
                os.close(fd)
                raise
            try:
                same = os.path.samestat(os.stat(self.path), os.fstat(fd))
            except OSError:
                same = False
            if same:
                self._fd, self.created = fd, created
                return
            # the scan that held the lock replaced or removed the file before letting go: the lock
            # taken is on a file no longer there; the one at the path now is the one to lock
            os.close(fd)
        raise WallcliError(f"cannot lock {self.path}: it keeps being replaced (another scan?)")

    def _format(self, line: dict) -> str:
        if self.columns is None:
            return self.encode(line) + "\n"
        return csv_record(flatten(line, self.columns))

    def start(self, kept: list[Entry] | None) -> None:
        """Start appending. ``kept`` None: the file is right as it is; otherwise it is to be
        replaced, atomically, by a fresh file holding the header and ``kept``'s lines, but only
        once this run stores its first line or ends well: a run that fails or is interrupted
        before that (an unreachable cluster, Ctrl-C at start-up) leaves the old file as it was,
        --force's old results included."""
        self._pending = kept
        if kept is None:
            self._fh = os.fdopen(self._fd, "a", encoding="utf-8", newline="")

    def _replace(self) -> None:
        from wallcli.io.writer import atomic_path, release_temporary

        kept, self._pending = self._pending, None
        header = [csv_record(self.columns)] if self.columns is not None else []
        new = None
        try:
            with atomic_path(self.path, force=True) as tmp:
                tmp.write_text("".join(header + [f"{e.raw}\n" for e in kept]), encoding="utf-8")
                # locked before the rename, and the lock goes with the file: there is no moment
                # when the path names an unlocked file another scan could take
                new = os.open(tmp, os.O_WRONLY | os.O_APPEND | getattr(os, "O_CLOEXEC", 0))
                release_temporary(tmp)  # the writer's own lock on it gives way to this one
                _lock(new, self.path)
        except OSError as exc:
            if new is not None:
                os.close(new)
            raise WallcliError(f"cannot write {self.path}: {_reason(exc)}") from None
        except BaseException:
            if new is not None:
                os.close(new)
            raise
        os.close(self._fd)
        self._fd = new
        self._fh = os.fdopen(self._fd, "a", encoding="utf-8", newline="")

    def append(self, line: dict) -> None:
        if self._pending is not None:
            self._replace()
        # one write of the whole line, then flush and fsync: the line is on disk before the next
        # one starts, and a kill can tear at most the line being written
        try:
            self._fh.write(self._format(line))
            self._fh.flush()
            os.fsync(self._fh.fileno())
        except OSError as exc:  # a full disk, a quota: the lines before this one are whole
            raise WallcliError(f"cannot write {self.path}: {_reason(exc)}") from None
        self.appended += 1

    def close(self) -> None:
        """End a run that went well: a replacement still pending (no line stored) is made now."""
        if self._pending is not None and self._fd is not None:
            self._replace()
        fh, fd, self._fh, self._fd = self._fh, self._fd, None, None
        try:
            if fh is not None:
                fh.close()
            elif fd is not None:
                os.close(fd)
        except OSError as exc:
            raise WallcliError(f"cannot write {self.path}: {_reason(exc)}") from None

    def abandon(self) -> None:
        """Close after a failure; a file this run created and never wrote a line to is removed
        (while still locked, so no other scan can have opened it meanwhile)."""
        self._pending = None  # the old file stays as it was: nothing new replaces it
        try:
            if self.created and not self.appended:
                self.path.unlink(missing_ok=True)
            self.close()
        except (OSError, WallcliError):  # a full disk refuses the unwritten rest again: the first error tells
            pass


def _reason(exc: OSError) -> str:
    text = exc.strerror or str(exc)
    return text[:1].lower() + text[1:]


def _lock(fd: int, path: Path) -> None:
    """An exclusive advisory lock on the open file ``fd``; an error naming ``path`` when another
    process holds one. flock, not lockf: a POSIX lock is dropped when the process closes *any*
    descriptor of the file, as reading it does."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock, as before
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        raise WallcliError(f"another wallcli scan is writing {path}",
                           hint="wait for it to end, or choose another -o") from None
    except OSError as exc:
        if exc.errno in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS):
            return  # a file system without locks (some network ones): carry on unlocked, as before
        raise WallcliError(f"cannot lock {path}: {_reason(exc)}") from None
