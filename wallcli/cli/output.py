"""The one place that prints. Data -> stdout (JSON or a rich table); everything else -> stderr."""

from __future__ import annotations

import json
import math
import sys
from contextlib import contextmanager
from typing import Any, Iterator

from rich.console import Console

console_err = Console(stderr=True, highlight=False)
console_out = Console(highlight=False)


def _clean(obj: Any) -> Any:
    """Make numpy scalars/arrays and non-finite floats JSON-safe (NaN/inf -> null, never invalid JSON)."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if hasattr(obj, "tolist") and not isinstance(obj, (str, bytes)):
        return _clean(obj.tolist())
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    return obj


def to_json(obj: Any) -> str:
    return json.dumps(_clean(obj), ensure_ascii=False, allow_nan=False)


def emit_json(obj: Any) -> None:
    """Exactly one JSON object (one line) on stdout, flushed: safe for pipes and --follow."""
    sys.stdout.write(to_json(obj) + "\n")
    sys.stdout.flush()


def log(message: str, *, wrap: bool = True) -> None:
    """A line for the reader on stderr; ``wrap=False`` for lines that name files (no break inside
    a path, so grep finds it)."""
    console_err.print(message, soft_wrap=not wrap)


def warn(message: str) -> None:
    from rich.markup import escape

    # messages carry file names, which may hold '[...]' (rich markup) of any kind
    console_err.print(f"[yellow]Warning:[/yellow] {escape(message)}", markup=True)


def print_table(title: str, columns: list[str], rows: list[list[Any]]) -> None:
    from rich.table import Table

    table = Table(title=title, title_justify="left")
    for i, col in enumerate(columns):
        table.add_column(col, justify="left" if i == 0 else "right")
    for row in rows:
        table.add_row(*(str(c) for c in row))
    console_out.print(table)


@contextmanager
def progress(description: str, total: int | None, *, enabled: bool = True) -> Iterator[Any]:
    """A rich progress bar on stderr; yields ``advance(n=1)``. Silent when stderr is not a terminal."""
    if not enabled or not console_err.is_terminal:
        yield lambda n=1: None
        return
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
    with Progress(*cols, console=console_err, transient=True) as bar:
        task = bar.add_task(description, total=total)
        yield lambda n=1: bar.advance(task, n)


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
