import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
os.environ.setdefault("MPLBACKEND", "Agg")


# Stopping the suite (Ctrl-C, `kill PID`) must stop it, and leave no worker behind. Two things
# stood in the way. (1) A command run in-process (run_cli, or main() itself) turns Ctrl-C and
# SIGTERM into exit code 1, as a command must: the test failed and the run went on to the next
# one, which started its own workers. The handlers record each signal (wallcli.errors'
# mark_interrupted, wrapped here, as install() resets the module's own flag on every main()), and
# the run stops as pytest stops on Ctrl-C. (2) SIGTERM outside a command ended pytest on the spot,
# its workers orphaned, and at exit concurrent.futures waited for any busy one: SIGTERM (and
# SIGHUP) now unwind like Ctrl-C, and the session ends by stopping the workers still running.
_stopped: list[int] = []


def _stop_run(signum, frame):
    raise KeyboardInterrupt


def pytest_configure(config):
    import signal

    import wallcli.errors as errors

    mark = errors.mark_interrupted
    if not getattr(mark, "suite", False):
        def recorded():
            _stopped.append(0)
            mark()

        recorded.suite = True
        errors.mark_interrupted = recorded
    for name in ("SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is not None and signal.getsignal(sig) is signal.SIG_DFL:
            signal.signal(sig, _stop_run)


def stop_if_interrupted() -> None:
    """Raise KeyboardInterrupt when a signal reached a command run in-process: the suite stops."""
    if _stopped:
        _stopped.clear()  # once: the session's own teardown then runs undisturbed
        raise KeyboardInterrupt


@pytest.fixture(autouse=True)
def _stop_after_an_interrupted_command():
    yield
    stop_if_interrupted()  # a test that called main() itself and went on after the signal


def pytest_sessionfinish(session, exitstatus):
    """No worker outlives the suite: multiprocessing's children still running (a pool or a Dask
    cluster an interrupted test left) are stopped, then killed (Dask's workers block SIGTERM)."""
    import multiprocessing

    children = multiprocessing.active_children()
    for p in children:
        p.terminate()
    for p in children:
        p.join(3)
        if p.is_alive():
            p.kill()
            p.join(3)


@pytest.fixture
def run_cli(capsys):
    """Run ``wallcli`` in-process; returns (exit_code, stdout, stderr)."""
    from wallcli.cli.app import main

    def run(*args):
        try:
            main([str(a) for a in args])
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        stop_if_interrupted()  # Ctrl-C or kill stops the suite, not only this command
        out, err = capsys.readouterr()
        return code, out, err

    return run
