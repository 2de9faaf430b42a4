"""Ctrl-C (SIGINT), `kill PID` (SIGTERM) and a closed terminal (SIGHUP) unwind the same way:
temporary outputs are removed, a training run saves its checkpoint, and the command exits 1 with
`Error: interrupted`. SIGTERM's default action would end the process on the spot and leave
`.NAME.XXXX.tmp.EXT` behind; Python's own SIGINT handler raises a bare KeyboardInterrupt (see
wallcli.errors.Interrupted for why not).

The first signal raises; later ones only set the flag, so a second Ctrl-C cannot break the clean-up
the first one started, nor land in main()'s own error handling. Once main() has settled the exit
code, :func:`settle` ignores them all: a signal during the interpreter's shut-down would otherwise
end the process by the signal itself (status 130, no message), as Python restores the default
actions before it exits."""
from __future__ import annotations

_raised = False


def install():
    """Install the handlers; returns what they replaced, for :func:`restore`."""
    import signal
    import sys
    import threading

    from wallcli import errors
    from wallcli.errors import Interrupted, mark_interrupted

    global _raised
    main_thread = threading.current_thread() is threading.main_thread()
    if main_thread and getattr(signal.getsignal(signal.SIGTERM), "wallcli", False):
        return {}  # already installed (by the console script, before its imports): keep its state
    _raised = False
    errors._interrupted = False  # main() run again in one process (tests) starts afresh

    def handler(signum, frame):
        global _raised
        mark_interrupted()  # in case the raise below lands where Python swallows it
        if not _raised:
            _raised = True
            raise Interrupted

    handler.wallcli = True
    previous = sys.unraisablehook

    def unraisable(info):
        # the raise landed in a weakref callback or __del__: Python would print a traceback and
        # carry on; the flag set above ends the command at its next output, or at its end
        if not issubclass(info.exc_type, Interrupted):
            previous(info)

    unraisable.wallcli = True
    if not getattr(previous, "wallcli", False):  # main() called again in one process: wrap once
        sys.unraisablehook = unraisable
    saved = {}
    if main_thread:
        saved = {sig: signal.getsignal(sig) for sig in _signals()}
        signal.signal(signal.SIGTERM, handler)
        # a shell starts background jobs with SIGINT ignored, nohup ignores SIGHUP: leave those
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            signal.signal(signal.SIGINT, handler)
        if hasattr(signal, "SIGHUP") and signal.getsignal(signal.SIGHUP) is signal.SIG_DFL:
            signal.signal(signal.SIGHUP, handler)  # the terminal closed: unwind as for `kill`
    return saved


def _signals():
    import signal

    return [signal.SIGINT, signal.SIGTERM] + ([signal.SIGHUP] if hasattr(signal, "SIGHUP") else [])


def settle() -> None:
    """The exit code is decided: from now on SIGINT, SIGTERM and SIGHUP are ignored (process-wide,
    and Python leaves ignored signals ignored through its shut-down)."""
    import signal
    import threading

    global _raised
    _raised = True  # a signal already caught but not yet handled must not raise either
    if threading.current_thread() is threading.main_thread():
        for sig in _signals():
            signal.signal(sig, signal.SIG_IGN)


def restore(saved) -> None:
    """main() called from Python (tests): give the caller its own handlers back."""
    import signal
    import threading

    global _raised
    _raised = True
    if threading.current_thread() is threading.main_thread():
        for sig, handler in (saved or {}).items():
            if handler is not None:
                signal.signal(sig, handler)
