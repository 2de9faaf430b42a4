"""Option parsing and input helpers shared by the command modules (stdlib + typer only)."""

from __future__ import annotations

import math
import os

import typer

from wallcli.errors import UsageError

ROI_HELP = ("Region of the wall to analyse, x,y,w,h in source pixels (origin top-left), at least 2x2 pixels "
            "(one chroma sample of 4:2:0 video). Default: whole frame.")
# said in the help of every option that draws a figure (check_png_names enforces it)
PNG_NAME = "The name must end in .png."


def force_help(what: str) -> str:
    """``--force``'s help, naming what it overwrites (each command writes different files)."""
    return f"Overwrite {what}; without --force, an output file that already exists is refused before any work starts."

# More threads than this only adds contention; 100000 of them once took 16 GB and ignored SIGTERM.
MAX_THREADS = 4 * (os.cpu_count() or 1)


def _fmt(x: float) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


class Number:
    """The parser (typer ``parser=``) of every numeric option: a finite number within its range.

    NaN, +-inf, out-of-range and malformed values are usage errors (exit 2) that name the option,
    before any work starts. One class for all of them, so a new option cannot forget a check;
    tests/test_option_sweep.py insists that every int or float option uses it.
    """

    def __init__(self, flag: str, lo: float, hi: float, *, integer: bool = False,
                 lo_open: bool = False, hi_open: bool = False) -> None:
        self.flag, self.lo, self.hi, self.integer = flag, lo, hi, integer
        self.lo_open, self.hi_open = lo_open, hi_open

    def range_text(self) -> str:
        if not (self.lo_open or self.hi_open):
            return f"from {_fmt(self.lo)} to {_fmt(self.hi)}"
        lo = f"{'more than' if self.lo_open else 'from'} {_fmt(self.lo)}"
        hi = f"{'less than' if self.hi_open else 'up to'} {_fmt(self.hi)}"
        return f"{lo}, {hi}"

    def describe(self) -> str:
        return f"{'an integer' if self.integer else 'a number'} {self.range_text()}"

    def __call__(self, value):
        # typer passes the default through too, as a number
        if isinstance(value, bool):
            raise UsageError(f"{self.flag} must be {self.describe()} (got {value!r})")
        if isinstance(value, (int, float)):
            x, shown = value, _fmt(value)
        else:
            shown = str(value)
            text = shown.strip()
            try:
                x = int(text, 10) if self.integer else float(text)
            except ValueError:  # also int() of more than 4300 digits
                x = None
            if x is None or (not self.integer and not text):
                raise UsageError(f"{self.flag} must be {self.describe()} (got {shown!r})") from None
        if self.integer and isinstance(x, float):
            if not x.is_integer():
                raise UsageError(f"{self.flag} must be {self.describe()} (got {shown})")
            x = int(x)
        if not self.integer and not math.isfinite(x):
            raise UsageError(f"{self.flag} must be {self.describe()} (got {shown})")
        below = x <= self.lo if self.lo_open else x < self.lo
        above = x >= self.hi if self.hi_open else x > self.hi
        if below or above:
            raise UsageError(f"{self.flag} must be {self.describe()} (got {shown})")
        return int(x) if self.integer else float(x)


def number_option(default, flag: str, *aliases: str, lo: float, hi: float, integer: bool = False,
                  lo_open: bool = False, hi_open: bool = False, help: str = "", **kwargs):
    """A ``typer.Option`` for a number, checked by :class:`Number`; its range is added to the help."""
    parse = Number(flag, lo, hi, integer=integer, lo_open=lo_open, hi_open=hi_open)
    text = f"{help} [{'integer' if integer else 'number'} {parse.range_text()}]".strip()
    return typer.Option(default, flag, *aliases, parser=parse, metavar="INTEGER" if integer else "NUMBER",
                        help=text, **kwargs)


def threads_option(help: str):
    """``--threads``, 0 (the library chooses) up to 4 threads per CPU core."""
    return number_option(0, "--threads", lo=0, hi=MAX_THREADS, integer=True,
                         help=f"{help} At most 4 per CPU core ({MAX_THREADS} on this machine).")


THREADS_HELP = "Decoder threads (0 = FFmpeg chooses)."


def parse_roi(text: str | None) -> tuple[int, int, int, int] | None:
    """'x,y,w,h' -> ints; malformed text is a usage error (exit 2), out-of-frame is checked later."""
    if text is None:
        return None  # an empty --roi "" is malformed (a script's unset variable), not the whole frame
    parts = text.replace(" ", "").split(",")
    try:
        values = tuple(int(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != 4:
        raise UsageError(f"--roi must be four integers x,y,w,h (got {text!r})")
    return values  # type: ignore[return-value]


def check_png_names(*named) -> None:
    """(flag, path) pairs of figure outputs: a figure is PNG whatever the name says, so a name that
    says otherwise (x.txt, x.jpg) is refused before any work (exit 2)."""
    for flag, path in named:
        if path is not None and os.path.splitext(str(path))[1].lower() != ".png":
            raise UsageError(f"{flag} writes a PNG; its name must end in .png (got {str(path)!r})")


def input_argument(help_text: str = "Video file, http(s)/rtsp URL, or '-' for a stream on stdin."):
    return typer.Argument(..., help=help_text, show_default=False)


def is_npz(path: str) -> bool:
    return str(path).lower().endswith(".npz")


def stream_option():
    """``--stream N``: which video stream of a file with several to read."""
    return number_option(None, "--stream", lo=0, hi=65535, integer=True,
                         help="Read the video stream with this index (as ffprobe numbers a file's streams). "
                              "Default: the first video stream that is not a cover picture; a file with several "
                              "says which was read.")


def stall_option(follow: bool = True):
    """``--stall-timeout SECONDS``: how long stdin or a FIFO may send nothing (``follow``: the
    command has --follow, whose default differs; the others must not mention it)."""
    default = "30, or for ever with --follow (a live feed may pause)" if follow else "30"
    return number_option(None, "--stall-timeout", lo=0, hi=1e6,
                         help="Seconds stdin or a pipe may send nothing before the command stops with an "
                              f"error saying it stalled; 0 waits for ever. Default: {default}. "
                              "Ctrl-C ends the wait at any time.")


def use_stream(index, stall: float | None = None, *, live: bool = False) -> None:
    """Make ``index`` (--stream) the stream every reader of this command opens, and ``stall``
    (--stall-timeout; None: the default, for ever when ``live``) how long its input may stall."""
    from wallcli.io.video import DEFAULT_STALL, STALL, STREAM

    STREAM.set(index)
    if stall is None:
        stall = 0 if live else DEFAULT_STALL
    STALL.set(float(stall) or None)


STRICT_HELP = ("Exit 1 when the view check finds the video is not a static view of a wall (camera motion, "
               "something moving in view, a cut, too little usable area). Without it such answers are "
               "undetermined, with the reason, and the exit status is 0.")


def strict_option():
    return typer.Option(False, "--strict", help=STRICT_HELP)


def refuse_view(source, view) -> None:
    """Under --strict: an unusable view is the input's error (exit 1, one line)."""
    if view and not view.get("usable", True):
        from wallcli.errors import WallcliError

        raise WallcliError(f"{source}: {view.get('reason') or 'not a static view of the wall'} (--strict)")


DEFLICKER_HELP = ("Leave aliased mains flicker in. By default a narrow line where lamps' 100/120 Hz flicker "
                  "lands at this frame rate (e.g. 10 Hz at 30 fps), whole-frame or as rolling-shutter bands, "
                  "is found and removed before analysis, and listed under 'corrections' in the JSON.")
EXPOSURE_HELP = ("Leave auto-exposure and gain steps and slow light drift in. By default whole-frame steps and "
                 "drift slower than about 8 s are found, divided out before analysis, and listed under "
                 "'corrections' in the JSON.")
SHAKE_HELP = ("Leave camera shake in. By default each frame's sub-pixel shift is measured on the wall's "
              "own features and, where the shifts explain the wall's changes, each bin's (or block's) "
              "response to them is fitted and removed (listed as 'shake' under 'corrections'). "
              "Motion the view check refuses is not made usable by it.")


def deflicker_option():
    return typer.Option(False, "--no-deflicker", help=DEFLICKER_HELP)


def exposure_option():
    return typer.Option(False, "--no-exposure", help=EXPOSURE_HELP)


def shake_option():
    return typer.Option(False, "--no-shake", help=SHAKE_HELP)


def corrections_of(no_deflicker: bool, no_exposure: bool, no_shake: bool = False):
    """The corrections to run (wallcli.camera.corrections.Options) from the --no-* options."""
    from wallcli.camera.corrections import Options

    return Options(deflicker=not no_deflicker, exposure=not no_exposure, shake=not no_shake)
