"""Ctrl-C (SIGINT) and `kill PID` (SIGTERM) unwind the same way: temporary outputs are removed, a
training run saves its checkpoint, and the command exits 1 with `Error: interrupted`. SIGTERM's
default action would end the process on the spot and leave `.NAME.XXXX.tmp.EXT` behind; Python's
own SIGINT handler raises a bare KeyboardInterrupt (see wallcli.errors.Interrupted for why not)."""
from __future__ import annotations


def install() -> None:
    import signal
    import sys
    import threading

    from wallcli.errors import Interrupted, mark_interrupted

    def handler(signum, frame):
        mark_interrupted()  # in case the raise below lands where Python swallows it
        raise Interrupted

    previous = sys.unraisablehook

    def unraisable(info):
        # the raise landed in a weakref callback or __del__: Python would print a traceback and
        # carry on; the flag set above ends the command at its next output, or at its end
        if not issubclass(info.exc_type, Interrupted):
            previous(info)

    unraisable.wallcli = True
    if not getattr(previous, "wallcli", False):  # main() called again in one process: wrap once
        sys.unraisablehook = unraisable
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, handler)
        # a shell starts background jobs with SIGINT ignored: leave that as it is
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            signal.signal(signal.SIGINT, handler)
