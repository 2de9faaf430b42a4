"""The one exception type users see. The CLI turns it into ``Error: ...`` and an exit code."""

from __future__ import annotations


class WallcliError(Exception):
    """A failure the user can act on: bad input, failed work. Exit code 1 by default."""

    exit_code = 1

    def __init__(self, message: str, hint: str | None = None, exit_code: int | None = None):
        super().__init__(message)
        self.message = message
        self.hint = hint
        if exit_code is not None:
            self.exit_code = exit_code

    def __str__(self) -> str:
        return self.message if not self.hint else f"{self.message} ({self.hint})"


class UsageError(WallcliError):
    """A malformed option value or a combination of options that makes no sense (exit 2)."""

    exit_code = 2


class Interrupted(KeyboardInterrupt):
    """Raised by the CLI's handlers of SIGINT (Ctrl-C) and SIGTERM (`kill PID`, which thus unwinds
    like Ctrl-C); every ``except KeyboardInterrupt`` catches it.

    A subclass, not KeyboardInterrupt itself: CPython 3.11 remembers a bare KeyboardInterrupt
    that passed through some C-level calls (``_Py_UnhandledKeyboardInterrupt``) and then ends the
    process with SIGINT even after the exception was handled and ``sys.exit(1)`` called (seen: 5
    of 150 Ctrl-Cs, and as many ``kill``s, of ``wallcli simulate`` exited -2 after printing
    ``Error: interrupted``). CPython tests for that exact type, so a subclass is left alone.
    """


# Set by those handlers. An exception raised from a signal handler is lost when the signal
# lands in a weakref callback or __del__ (seen twice in 450 kills), so outputs check this flag too.
_interrupted = False


def mark_interrupted() -> None:
    global _interrupted
    _interrupted = True


def raise_if_interrupted() -> None:
    if _interrupted:
        raise Interrupted
