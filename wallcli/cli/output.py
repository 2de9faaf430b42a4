"""The one place that prints. Data -> stdout (JSON or a rich table); everything else -> stderr."""

from __future__ import annotations

import errno
import io
import json
import os
import re
import sys
from contextlib import contextmanager
from typing import Any, Iterator

from rich.console import Console

from wallcli.errors import WallcliError

# markup off: a file named '[/x].mp4' is text, not a (broken) style tag
console_err = Console(stderr=True, highlight=False, markup=False)
console_out = Console(highlight=False, markup=False)
# A file name that is not valid UTF-8 reaches Python as str with lone surrogates (PEP 383).
_SURROGATE = re.compile("[\ud800-\udfff]")


def _clean(obj: Any) -> Any:
    """Make numpy scalars/arrays and non-finite floats JSON-safe (NaN/inf -> null, never invalid JSON):
    the conversion the Python API (wallcli.api) applies too."""
    from wallcli.io.jsonfile import plain

    return plain(obj)


def to_json(obj: Any) -> str:
    """Valid JSON whatever the strings hold: lone surrogates (the undecodable bytes of a file name
    that is not UTF-8) are written as \\udcXX escapes, which json.loads turns back into the same
    str (os.fsencode of it gives the original bytes); raw, they would put invalid UTF-8 on stdout."""
    from wallcli.io.text import escape_surrogates

    return escape_surrogates(json.dumps(_clean(obj), ensure_ascii=False, allow_nan=False))


def printable(text: Any) -> str:
    """``text`` for a terminal: an undecodable byte of a file name shown as \\xff."""
    def escape(m: re.Match) -> str:
        c = ord(m.group())
        return f"\\x{c - 0xDC00:02x}" if 0xDC80 <= c <= 0xDCFF else f"\\u{c:04x}"

    return _SURROGATE.sub(escape, str(text))


def emit_json(obj: Any) -> None:
    """Exactly one JSON object (one line) on stdout, flushed: safe for pipes and --follow."""
    sys.stdout.write(to_json(obj) + "\n")
    sys.stdout.flush()


def log(message: str, *, wrap: bool = True) -> None:
    """A line for the reader on stderr; ``wrap=False`` for lines that name files (no break inside
    a path, so grep finds it)."""
    console_err.print(printable(message), soft_wrap=not wrap)


def wrote(*outputs) -> None:
    """One line on stderr naming what a command wrote: (path, what it holds) pairs; None paths
    (outputs not asked for) are left out. Called once the outputs are in place, never before."""
    # '-': the data went to stdout, which is no file to name
    parts = [f"{printable(p)} ({what})" if what else printable(p) for p, what in outputs
             if p is not None and str(p) != "-"]
    if parts:
        log("wrote " + "; ".join(parts), wrap=False)


def warn(message: str) -> None:
    from rich.text import Text

    console_err.print(Text.assemble(("Warning:", "yellow"), " ", printable(message)))


# a cell that reads as figures ("12.3", "-", "0.1 / 0.2 / 0.3", "0 0.98 0.02") aligns right
_NUMBER = re.compile(r"-|[-+0-9.e ]*[0-9][-+0-9.e /%]*")


def print_table(title: str, columns: list[str], rows: list[list[Any]], *, pad_edge: bool = False) -> None:
    """``pad_edge``: kept for callers that ask; tables have no edge padding either way."""
    from rich import box
    from rich.table import Table
    from rich.text import Text

    # the title is its own unwrapped line: scripts grep it ("count = 1") and a long path must
    # not split it across lines, as a table title wrapped to the table's width would
    console_out.print(Text(printable(title)), soft_wrap=True)
    # a rule under the header and no column borders: borders cost 3 characters a column, and
    # five classes beside a window's start, answer and signal must fit 80 columns
    table = Table(box=box.SIMPLE_HEAD, show_edge=False, pad_edge=pad_edge, collapse_padding=True)
    for i, col in enumerate(columns):
        numeric = i > 0 and all(_NUMBER.fullmatch(str(r[i])) for r in rows if i < len(r))
        table.add_column(printable(col), justify="right" if numeric else "left")
    for row in rows:
        table.add_row(*(printable(c) for c in row))
    console_out.print(table)


def print_lines(lines: list[str], *, hang: int = 0) -> None:
    """Lines of text on stdout (notes and footnotes under a table), wrapped to the terminal's width;
    ``hang``: indent of a wrapped line's continuation (under the text of a footnote, not its number)."""
    import textwrap

    for line in lines:
        text = printable(line)
        if hang:
            text = textwrap.fill(text, max(console_out.width, 2 * hang), subsequent_indent=" " * hang,
                                 break_long_words=False, break_on_hyphens=False)
        console_out.print(text)


# --------------------------------------------------------------------------------------- stdout
READER_LEFT = "stdout was closed by its reader before the output was complete"


class StdoutError(WallcliError):
    """stdout cannot take the data: the user's environment (a full disk, a closed stdout), not a bug."""


def _reason(exc: BaseException | None) -> str:
    if isinstance(exc, OSError) and exc.errno:
        text = os.strerror(exc.errno)
        return text[:1].lower() + text[1:]
    return "it is closed"


class _GuardedStdout:
    """sys.stdout while a command runs: a failed write or flush raises :class:`StdoutError`
    (one error line, exit 1) wherever it happens (our JSON and tables, click's help, print),
    a reader that went away (BrokenPipeError) included: click would catch that one itself and
    exit 1 saying nothing."""

    def __init__(self, stream) -> None:
        self._stream = stream

    def _call(self, name: str, *args):
        if self._stream is None:  # started with stdout closed (`>&-`): Python sets sys.stdout to None
            raise StdoutError(f"cannot write to stdout: {_reason(None)}")
        try:
            return (getattr(self._stream, name) if isinstance(name, str) else name)(*args)
        except BrokenPipeError:
            raise StdoutError(READER_LEFT) from None
        except UnicodeError:
            raise
        except (OSError, ValueError) as exc:  # ValueError: write to a closed file
            raise StdoutError(f"cannot write to stdout: {_reason(exc)}") from None

    def write(self, text: str) -> int:
        raw = getattr(self._stream, "buffer", None)
        if isinstance(raw, io.RawIOBase):
            return self._call(_write_all, self._stream, raw, text)
        return self._call("write", text)

    def flush(self) -> None:
        self._call("flush")

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def _write_all(stream, raw, text: str) -> int:
    """Write ``text`` whole to ``raw``, the unbuffered file under ``stream`` (``python -u``,
    PYTHONUNBUFFERED=1, common in containers). There the text layer writes straight to it and
    ignores a short write's count: a nearly full disk or a reader that left mid-way cut the
    output and the command still exited 0. Here a short write is followed by another, which
    fails with the reason (ENOSPC, EPIPE)."""
    data = text.encode(stream.encoding or "utf-8", stream.errors or "strict")
    view, done = memoryview(data), 0
    while done < len(data):
        n = raw.write(view[done:])
        if not n:  # None: a non-blocking stdout that is full; 0: nothing taken
            raise OSError(errno.EAGAIN if n is None else errno.ENOSPC, "stdout took no more data")
        done += n
    return len(text)


@contextmanager
def guarded_stdout() -> Iterator[None]:
    """Run a command with sys.stdout guarded; data still buffered is flushed at the end, inside,
    so that its failure is reported like any other."""
    real = sys.stdout
    sys.stdout = _GuardedStdout(real)
    try:
        yield
        sys.stdout.flush()
    finally:
        sys.stdout = real


def abandon_stdout() -> None:
    """After stdout failed: point the process's fd 1 at /dev/null, so that the interpreter's last
    flush of what is still buffered does not print a traceback and exit 120. Only for the real
    stdout (not a test's capture)."""
    stream = sys.stdout
    if stream is None or stream is not sys.__stdout__:
        return
    try:
        fd = stream.fileno()
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, fd)
        os.close(null)
    except (OSError, ValueError):
        pass


@contextmanager
def progress(description: str, total: int | None, *, enabled: bool = True, delay: float = 0.0) -> Iterator[Any]:
    """A rich progress bar on stderr; yields ``advance(n=1)``. Silent when stderr is not a terminal.
    ``delay``: seconds before it appears, so that work shorter than that shows none."""
    if not enabled or not console_err.is_terminal:
        yield lambda n=1: None
        return
    if delay > 0:
        with _delayed(description, total, delay) as advance:
            yield advance
        return
    with _bar(description, total) as (bar, task):
        bar.start()
        yield lambda n=1: bar.advance(task, n)


@contextmanager
def _bar(description: str, total: int | None) -> Iterator[Any]:
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    cols = [TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn()]
    if total:
        cols.append(TimeRemainingColumn())
    bar = Progress(*cols, console=console_err, transient=True)
    try:
        yield bar, bar.add_task(description, total=total)
    finally:
        if bar.live.is_started:  # stop() of a bar never shown would still print a blank line on some terminals
            bar.stop()


@contextmanager
def _delayed(description: str, total: int | None, delay: float) -> Iterator[Any]:
    """The bar started by a timer: the work may not advance it for a long while (a first clip)."""
    import threading

    with _bar(description, total) as (bar, task):
        lock = threading.Lock()
        done = False

        def show() -> None:
            with lock:
                if not done:
                    bar.start()

        timer = threading.Timer(delay, show)
        timer.daemon = True
        timer.start()
        try:
            yield lambda n=1: bar.advance(task, n)
        finally:
            with lock:  # after this, show() cannot start a bar that _bar has already stopped
                done = True
                timer.cancel()


@contextmanager
def batch_progress(description: str, total: int, unit: str = "videos", *, enabled: bool = True) -> Iterator[Any]:
    """A bar for many items (``wallcli scan``): done / total, hours of video, rate, ETA, failures.

    Yields ``update(hours, failed)``, called after each item. Silent when stderr is not a terminal.
    """
    if not enabled or not console_err.is_terminal:
        yield lambda hours, failed: None
        return
    import time

    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    cols = [TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TextColumn(unit),
            TextColumn("{task.fields[hours]:.2f} h of video"), TextColumn("{task.fields[rate]}"),
            TimeRemainingColumn(), TextColumn("{task.fields[failed]}")]
    t0 = time.monotonic()
    with Progress(*cols, console=console_err, transient=True) as bar:
        task = bar.add_task(description, total=total, hours=0.0, rate="", failed="")

        def update(hours: float, failed: int) -> None:
            bar.advance(task, 1)
            done = bar.tasks[0].completed
            rate = done / max(time.monotonic() - t0, 1e-9)
            bar.update(task, hours=hours, rate=f"{rate:.2f} {unit}/s" if rate >= 0.1 else f"{60 * rate:.2f} {unit}/min",
                       failed=f"[red]{failed} failed[/red]" if failed else "0 failed")

        yield update
