"""The typer app and ``main()``: the only place that maps failures to exit codes.

Command modules are imported here, so they import only typer and the standard library at
module level; numpy, PyAV, OpenCV, onnxruntime and matplotlib load inside the commands, which
keeps ``wallcli --help`` and ``--version`` fast.
"""

from __future__ import annotations

import os
import sys

import typer

from wallcli import __version__

HELP = """\
Learn what happens in a hidden part of a room by staring at a blank wall.

People moving out of the camera's view change the light on a visible wall by 0.1-1 %.
wallcli recovers that signal from an ordinary video: it removes each pixel's temporal
mean, averages the wall over many pixels (noise falls as 1/sqrt(pixels)), and reads the
resulting space-time plots.

\b
Pipeline:  wallcli snr clip.mp4 --roi auto        # any signal, and where?
           wallcli stplot clip.mp4 -o p.npz --png p.png
           wallcli count p.npz --json              # 0, 1 or 2 people
           wallcli activity clip.mp4               # what they are doing
           wallcli amplify clip.mp4 amp.mp4        # see the invisible signal
           wallcli report clip.mp4 -o report.html  # one page to hand over

Exit codes: 0 success, 1 input or work failed, 2 usage error.  WALLCLI_DEBUG=1 shows tracebacks.
"""

app = typer.Typer(
    help=HELP,
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
    context_settings={"help_option_names": ["-h", "--help"]},
)


def _version(value: bool) -> None:
    if value:
        print(f"wallcli {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", "-V", callback=_version, is_eager=True, help="Print the version and exit."
    ),
) -> None:
    pass


def _register() -> None:
    # One module per command; each imports only typer and the standard library at module level.
    import importlib

    from wallcli.cli.helpstyle import Command

    for name in ("stplot", "amplify", "snr", "count", "activity", "track", "simulate", "train", "evaluate", "report",
                 "scan"):
        app.command(name, cls=Command)(getattr(importlib.import_module(f"wallcli.cli.{name}"), name))


_register()


def _debug() -> bool:
    return os.environ.get("WALLCLI_DEBUG", "") not in ("", "0")


def _say(message: str) -> None:
    # One line on stderr, always: scripts grep for it and humans read it (stderr may be closed: 2>&-)
    from wallcli.cli.output import printable

    if sys.stderr is not None:
        try:
            sys.stderr.write(f"Error: {printable(' '.join(str(message).split()))}\n")
            sys.stderr.flush()
        except (OSError, ValueError):
            pass


def _click_exceptions():
    # typer >= 0.16 vendors click as typer._click; older ones depend on click itself. The vendored
    # one first: click may be installed beside it (dask needs it), but typer raises its own.
    try:
        from typer._click.exceptions import ClickException, UsageError
        from typer.exceptions import Abort, Exit
    except ImportError:
        from click.exceptions import Abort, ClickException, Exit, UsageError
    return Abort, ClickException, Exit, UsageError


def _fill_closed_fds() -> None:
    """A standard stream closed by the caller (`>&-`) leaves its fd free, and the next file we open
    would get it: FFmpeg's or a library's writes to 'stdout' would then land in our output file.
    Park /dev/null there (Python already set sys.stdout to None, so our own data still fails)."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            null = os.open(os.devnull, os.O_RDWR)
            if null != fd:
                os.dup2(null, fd)
                os.close(null)


def main(argv: list[str] | None = None) -> None:
    """The console script (``argv`` None) or a call from Python with ``argv``; ends with SystemExit
    and a code of 0, 1 or 2, whatever happens, a signal during shut-down included."""
    from wallcli.cli import _signals

    saved = _signals.install()
    try:
        code = _run(argv)
    except KeyboardInterrupt:  # the one signal that raises (see _signals) landed after _run decided
        _say("interrupted")
        code = 1
    finally:
        if argv is None:
            _signals.settle()
        else:
            _signals.restore(saved)
    sys.exit(code)


def _forget_stream() -> None:
    """--stream, --stall-timeout and --follow's --idle-timeout are one command's choice: never the next one's, nor a library
    caller's after it."""
    video = sys.modules.get("wallcli.io.video")
    if video is not None:
        video.STREAM.set(None)
        video.STALL.set(video.DEFAULT_STALL)
        video.FOLLOW_IDLE.set(None)


def _run(argv: list[str] | None) -> int:
    """Run the command; print its error line; return the exit code."""
    try:
        return _run_command(argv)
    finally:
        _forget_stream()


def _run_command(argv: list[str] | None) -> int:
    from wallcli.cli.output import READER_LEFT, StdoutError, abandon_stdout, guarded_stdout, printable
    from wallcli.errors import WallcliError, raise_if_interrupted

    Abort, ClickException, Exit, ClickUsageError = _click_exceptions()

    import warnings

    def _show(message, category, *args, **kwargs):  # warnings: one line on stderr, no source line
        if sys.stderr is not None:
            sys.stderr.write(f"Warning: {printable(message)}\n")

    warnings.showwarning = _show
    if argv is None:
        _fill_closed_fds()
    command = typer.main.get_command(app)
    try:
        with guarded_stdout():
            rv = command.main(args=argv, prog_name="wallcli", standalone_mode=False)
            raise_if_interrupted()  # killed, but the exception was swallowed on the way: still exit 1
        # Without standalone mode, click *returns* the code of an Exit it caught (Ctrl-C -> 130);
        # the contract knows 0, 1 and 2 only: an interrupted job is work that failed (1).
        if isinstance(rv, int) and rv:
            if rv == 130:
                _say("interrupted")
                return 1
            return rv if rv in (1, 2) else 1
        return 0
    except StdoutError as exc:
        abandon_stdout()
        _say(str(exc))
        return 1
    except WallcliError as exc:
        if _debug():
            raise
        _say(str(exc))
        return exc.exit_code
    except Exit as exc:
        return exc.exit_code if exc.exit_code in (0, 1, 2) else 1
    except Abort:
        _say("interrupted")
        return 1
    except ClickUsageError as exc:
        if _debug():
            raise
        if type(exc).__name__ == "NoArgsIsHelpError":  # bare `wallcli` / `wallcli CMD`: show help
            if sys.stderr is not None:
                sys.stderr.write(exc.ctx.get_help() + "\n" if exc.ctx else "")
            return 2
        path = exc.ctx.command_path if exc.ctx else "wallcli"
        _say(f"{exc.format_message()} (see '{path} --help')")
        return 2
    except ClickException as exc:
        if _debug():
            raise
        _say(exc.format_message())
        return exc.exit_code if exc.exit_code in (1, 2) else 1
    except KeyboardInterrupt:
        if _debug():
            raise
        _say("interrupted")
        return 1
    except BrokenPipeError:
        # `wallcli ... | head`: the reader left before the output was whole. Not a success (a
        # Unix tool would die of SIGPIPE, a non-zero status; the contract's is 1), so say so in
        # the one line every failure gets: a bare 1 looked like a crash with nothing to read.
        abandon_stdout()
        _say(READER_LEFT)
        return 1
    except MemoryError:
        if _debug():
            raise
        _say("out of memory")
        return 1
    except Exception as exc:  # noqa: BLE001 - the last line of defence keeps the one-line promise
        if _debug():
            raise
        _say(f"internal error: {type(exc).__name__}: {exc} (set WALLCLI_DEBUG=1 for a traceback and report it)")
        return 1
