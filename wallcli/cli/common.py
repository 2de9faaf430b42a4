"""Option parsing and input helpers shared by the command modules (stdlib + typer only)."""

from __future__ import annotations

import typer

from wallcli.errors import UsageError

ROI_HELP = "Region of the wall to analyse, x,y,w,h in source pixels (origin top-left). Default: whole frame."
FORCE_HELP = "Overwrite existing output files."
THREADS_HELP = "Decoder threads (0 = FFmpeg chooses)."


def parse_roi(text: str | None) -> tuple[int, int, int, int] | None:
    """'x,y,w,h' -> ints; malformed text is a usage error (exit 2), out-of-frame is checked later."""
    if text is None or text == "":
        return None
    parts = text.replace(" ", "").split(",")
    try:
        values = tuple(int(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != 4:
        raise UsageError(f"--roi must be four integers x,y,w,h (got {text!r})")
    return values  # type: ignore[return-value]


def input_argument(help_text: str = "Video file, http(s)/rtsp URL, or '-' for a stream on stdin."):
    return typer.Argument(..., help=help_text, show_default=False)


def is_npz(path: str) -> bool:
    return str(path).lower().endswith(".npz")
