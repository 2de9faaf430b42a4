"""The labelled clips of a folder: ``labels.csv`` or the ``.json`` sidecars of ``wallcli simulate``.

``labels.csv`` needs the columns ``file``, ``people`` and ``activity`` (``people`` counts the
people who *move*: someone standing still is 0, as ``wallcli count`` counts); ``detectable`` (0/1)
and ``snr_db`` (the known SNR; empty for an empty room) are optional and every other column is
ignored. A sidecar's ``people`` counts everyone in the room, so a count's truth there is the number
of its ``activities`` other than ``none`` (what tests/test_examples.py checks the shipped models
against). A labels.csv that cannot be read is a failure of the whole run (exit 1, naming the line);
a clip that is missing is not: it becomes that clip's error row. A sidecar is one clip's labels, so
a damaged one (beside its video) skips that clip, with the reason, rather than failing the run.
Every clip must lie inside the folder once links are resolved (a name relative to it, or an
absolute path into it): one that leads out of it (``../x.mp4``, ``/dev/zero``) fails the run,
naming its row, as does one that is not a regular file (a FIFO would block the run), and a
labels.csv that is not a regular file is refused as such.
Two names for one file (``a.mp4``, ``./a.mp4``, a hard link or symlink to it) are one clip listed
twice: an error, as any duplicate is, since scoring it twice would weigh it double; so are two
byte-identical copies. A sidecar without ``activities`` gives the count's truth from ``moving``
(what ``wallcli simulate`` writes), else from ``people``.
"""
from __future__ import annotations

import csv
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from wallcli.errors import WallcliError
from wallcli.io import jsonfile

LABELS = "labels.csv"
REQUIRED = ("file", "people", "activity")
# A row is a file name and a few numbers; a longer line is not labels, and is refused before it is
# read whole (a 1 GB line once took 2 GB of memory before the csv module gave up on it).
MAX_LINE = 64 * 1024


@dataclass(frozen=True)
class Clip:
    file: str  # as the labels name it (relative to the folder, or an absolute path into it)
    path: Path
    people: int  # moving people
    activity: str
    detectable: bool | None  # None: not given
    persons: int  # everyone in the room, still or not: activity is defined for at most one
    snr_db: float | None = None  # the labels' SNR; None for an empty room or without the column

    def truth(self, task: str) -> Any:
        return self.people if task == "count" else self.activity

    def empty(self, task: str) -> bool:
        """An empty room: nobody moves (and, for activity, the label says so)."""
        return self.people == 0 and (task == "count" or self.activity == "none")


@dataclass(frozen=True)
class Labels:
    clips: list[Clip]  # in the labels' order
    source: str  # 'labels.csv' or 'sidecars'
    has_snr: bool  # the labels give each clip's SNR (an snr_db column)
    damaged: list[tuple[str, str]] = field(default_factory=list)  # (clip, why its sidecar cannot be used)
    files: list[Path] = field(default_factory=list)  # the label files read: labels.csv, or every .json looked at


def read_labels(folder: str | Path) -> Labels:
    d = Path(folder)
    if not d.exists():
        raise WallcliError(f"no such folder: {folder}")
    if not d.is_dir():
        raise WallcliError(f"{folder} is not a folder; give the folder that holds the clips and their labels")
    if (d / LABELS).is_file():
        clips, has_snr = _from_csv(d)
        return Labels(clips, LABELS, has_snr, files=[d / LABELS])
    if os.path.lexists(d / LABELS):  # a device, a FIFO, a folder or a broken link: there, but not labels
        raise WallcliError(f"{d / LABELS} is not a regular file ({_kind(d / LABELS)}); labels.csv must be "
                           "a text file of one row per clip")
    clips, damaged = _from_sidecars(d)
    if not clips:
        why = f" ({len(damaged)} damaged: {damaged[0][1]})" if damaged else ""
        raise WallcliError(f"{folder} has no labels: looked for {LABELS} (columns {', '.join(REQUIRED)}) and for "
                           f"*.json sidecars with 'people' and 'activity' (as 'wallcli simulate' writes them){why}")
    return Labels(clips, "sidecars", False, damaged, files=sorted(d.glob("*.json")))


def _inside(d: Path, named: list[tuple[str, Clip]], source: Path | None = None) -> None:
    """Fail on an entry whose clip is not inside the folder once links are resolved (``../x.mp4``,
    ``/dev/zero``, an absolute path elsewhere, a symlink out): labels describe the clips beside
    them, and a labels file handed over with a folder must not make evaluate or train read
    whatever else the machine holds."""
    root = d.resolve()
    for where, c in named:
        row = f"{source} {where}" if source else f"{d / where}"
        try:
            target = c.path.resolve()
        except (OSError, RuntimeError, ValueError) as exc:  # a link loop, a NUL in the name
            raise WallcliError(f"{row} names {c.file!r}, which cannot be resolved ({exc})") from None
        if not target.is_relative_to(root):
            raise WallcliError(f"{row} names {c.file!r}, which is outside {d} (it leads to {target}); "
                               "put the clip itself (not a link to it) in the folder")
        try:
            special = target.exists() and not target.is_file()
        except OSError:  # unreadable: that clip's row says why, later
            special = False
        if special:  # reading a FIFO or a device would block or never end
            raise WallcliError(f"{row} names {c.file!r}, which is {_kind(target)}, not a video file")


def _kind(path: Path) -> str:
    import stat

    try:
        mode = os.stat(path).st_mode
    except OSError:
        return "a broken link"
    return ("a FIFO" if stat.S_ISFIFO(mode) else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
            else "a folder" if stat.S_ISDIR(mode) else "a socket" if stat.S_ISSOCK(mode) else "not a file")


def _no_duplicates(source: Path, named: list[tuple[str, Clip]]) -> None:
    """Fail on two entries that name one file, however spelled (``a.mp4``, ``./a.mp4``, its full
    path) or reached (a hard link or symlink): by its spelling, and by device and inode if it exists
    (``sub/../a.mp4`` names a.mp4 even where no ``sub`` exists, so both are looked at)."""
    seen: dict[Any, tuple[str, Clip]] = {}
    for where, c in named:
        keys: list[Any] = [os.path.normcase(os.path.normpath(os.path.abspath(c.path)))]
        try:
            st = os.stat(c.path)
            keys.append((st.st_dev, st.st_ino))
        except (OSError, ValueError):  # missing (its row's error later) or an unusable name
            pass
        for key in keys:
            if key in seen:
                first, other = seen[key]
                raise WallcliError(f"{source} names one clip twice: {first} ({other.file!r}) and {where} "
                                   f"({c.file!r}); list each clip once")
        seen.update((key, (where, c)) for key in keys)
    _no_copies(source, named)


def _no_copies(source: Path, named: list[tuple[str, Clip]]) -> None:
    """Fail on two entries whose files are byte-identical copies: one recording scored twice
    weighs double, whatever its names. Only files of one size are hashed (copies are rare)."""
    from wallcli.infer.card import sha256_file

    by_size: dict[int, list[tuple[str, Clip]]] = {}
    for where, c in named:
        try:
            by_size.setdefault(os.stat(c.path).st_size, []).append((where, c))
        except (OSError, ValueError):
            pass
    for group in (g for g in by_size.values() if len(g) > 1):
        seen: dict[str, tuple[str, Clip]] = {}
        for where, c in group:
            try:
                digest = sha256_file(c.path)
            except OSError:
                continue
            if digest in seen:
                first, other = seen[digest]
                raise WallcliError(f"{source} names one recording twice: {first} ({other.file!r}) and {where} "
                                   f"({c.file!r}) are byte-identical copies; list each clip once")
            seen[digest] = (where, c)


def _from_csv(d: Path) -> tuple[list[Clip], bool]:
    path = d / LABELS
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            reader = csv.DictReader(_bounded_lines(f, path))
            header = [h.strip() for h in reader.fieldnames or []]
            missing = [c for c in REQUIRED if c not in header]
            if missing:
                raise WallcliError(f"{path} lacks the column(s) {', '.join(missing)} (needs {', '.join(REQUIRED)}; "
                                   f"has {', '.join(header) or 'none'})")
            reader.fieldnames = header
            has_snr = "snr_db" in header
            named = [(f"line {n}", _csv_row(path, n, row, has_snr)) for n, row in enumerate(reader, start=2)
                     if any((v or "").strip() for v in row.values() if isinstance(v, str))]
    except csv.Error as exc:  # e.g. a quoted cell that runs over many lines
        raise WallcliError(f"cannot read {path} line {reader.line_num}: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise WallcliError(f"cannot read {path}: {exc}") from None
    if not named:
        raise WallcliError(f"{path} lists no clips")
    _inside(d, named, path)
    _no_duplicates(path, named)
    return [c for _, c in named], has_snr


def _bounded_lines(f, path: Path):
    for n, line in enumerate(iter(lambda: f.readline(MAX_LINE + 1), ""), start=1):
        if len(line) > MAX_LINE:
            raise WallcliError(f"{path} line {n} is longer than {MAX_LINE} characters; labels.csv holds "
                               "one short row per clip")
        yield line


def _csv_row(path: Path, line: int, row: dict, has_snr: bool) -> Clip:
    where = f"{path} line {line}"
    name = (row.get("file") or "").strip()
    if not name:
        raise WallcliError(f"{where}: empty 'file'")
    people = _people(row.get("people"), where)
    activity = (row.get("activity") or "").strip()
    if not activity:
        raise WallcliError(f"{where}: empty 'activity'")
    det = (row.get("detectable") or "").strip()
    if det not in ("", "0", "1"):
        raise WallcliError(f"{where}: 'detectable' must be 0 or 1 (got {det!r})")
    snr = _snr(row.get("snr_db"), people, where) if has_snr else None
    return Clip(name, path.parent / name, people, activity, None if det == "" else det == "1", people, snr)


def _snr(value: Any, people: int, where: str) -> float | None:
    text = (value or "").strip()
    if not text:
        if people:  # the band table would have to guess, so say so now
            raise WallcliError(f"{where}: empty 'snr_db' where people = {people} (an empty cell "
                               "means an empty room; give its SNR, or drop the column to use the measured SNR)")
        return None
    try:
        x = float(text)
    except ValueError:
        x = math.nan
    if not math.isfinite(x):
        raise WallcliError(f"{where}: 'snr_db' must be a number of dB (got {text!r})")
    return x



def _people(value: Any, where: str) -> int:
    try:
        n = int(str(value).strip())
    except (TypeError, ValueError):
        raise WallcliError(f"{where}: 'people' must be a whole number (got {value!r})") from None
    if n < 0:
        raise WallcliError(f"{where}: 'people' must be >= 0 (got {n})")
    return n


def _from_sidecars(d: Path) -> tuple[list[Clip], list[tuple[str, str]]]:
    """(clips, damaged). A .json that cannot be read or lacks a label is a damaged sidecar when a
    video shares its name; without one it is some other file (a report, another tool's output)."""
    named, damaged = [], []
    for side in sorted(d.glob("*.json")):
        beside = [p for p in sorted(d.glob(side.stem + ".*")) if p.suffix.lower() != ".json"]
        try:
            named.append((side.name, _sidecar(d, side, beside)))
        except LookupError:
            continue
        except (OSError, UnicodeDecodeError, json.JSONDecodeError, WallcliError) as exc:
            if beside:
                why = str(exc) if isinstance(exc, WallcliError) else f"{side.name}: {exc}"
                damaged.append((beside[0].name, "damaged sidecar: " + " ".join(why.split())))
    _inside(d, named)
    _no_duplicates(d, named)
    return [c for _, c in named], damaged


def _sidecar(d: Path, side: Path, beside: list[Path]) -> Clip:
    """The clip a sidecar labels; LookupError: not a sidecar at all."""
    meta = jsonfile.loads(side.read_text(encoding="utf-8"), allow_nan=True)
    keys = [k for k in ("people", "activity") if isinstance(meta, dict) and k in meta]
    if not keys:
        raise LookupError(side.name)
    if len(keys) == 1:
        raise WallcliError(f"{side.name} has {keys[0]!r} but not {({'people', 'activity'} - set(keys)).pop()!r}")
    where = side.name
    acts = meta.get("activities")
    if isinstance(acts, list) and all(isinstance(a, str) for a in acts):
        moving = sum(a != "none" for a in acts)  # a still person is not counted (count's task)
    elif "moving" in meta:  # what simulate writes: the people who move, what count answers
        moving = _people(meta["moving"], where + " 'moving'")
        if moving > _people(meta["people"], where):
            raise WallcliError(f"{where}: 'moving' ({moving}) is more than 'people' ({meta['people']})")
    else:
        moving = _people(meta["people"], where)
    video = meta.get("video")
    if isinstance(video, str) and video and (d / Path(video).name).exists():
        target = d / Path(video).name
    else:  # the video beside it: same name, any other extension
        target = beside[0] if beside else d / (side.stem + ".mp4")
    det = meta.get("detectable")
    return Clip(target.name, target, moving, str(meta["activity"]).strip(),
                None if det is None else bool(det), _people(meta["people"], where))
