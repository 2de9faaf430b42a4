"""Stopping the test suite stops it: Ctrl-C or `kill PID` while a test's workers run ends pytest
within seconds, no later test runs, and no worker process survives (tests/conftest.py says why
that once failed: a command run in-process turned the signal into its exit code 1, and SIGTERM
left the workers orphaned)."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent

# the first test keeps two worker processes busy; the second must never run
IN_PROCESS = '''
def test_workers(run_cli, tmp_path):
    run_cli("simulate", "--dataset", "400", "--task", "count", "--jobs", "2", "-o", tmp_path / "ds")


def test_later():
    open({marker!r}, "w").close()
'''
EXECUTOR = '''
import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor


def test_workers():
    pool = ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn"))
    assert [f.result() for f in [pool.submit(time.sleep, 120) for _ in range(2)]]


def test_later():
    open({marker!r}, "w").close()
'''


def _session(sid: int) -> list[int]:
    """The live (not zombie) processes of session ``sid``: pytest and every process it started."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()  # after 'pid (comm) '
        if int(fields[3]) == sid and fields[0] != "Z":
            found.append(int(entry.name))
    return found


def _default_sigint():
    # a shell starts background jobs with SIGINT ignored, and children inherit that: the inner
    # pytest must receive Ctrl-C as a terminal's foreground job does
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads the process table from /proc")
@pytest.mark.parametrize("body,sig,group", [
    (IN_PROCESS, "SIGINT", True),    # Ctrl-C in a terminal: the whole foreground group
    (IN_PROCESS, "SIGTERM", False),  # `kill PID`: pytest alone
    (EXECUTOR, "SIGTERM", False),
], ids=["command-ctrl-c", "command-kill", "pool-kill"])
def test_stopping_the_suite_stops_it_and_its_workers(tmp_path, body, sig, group):
    marker = tmp_path / "later-test-ran"
    inner = tmp_path / "test_inner.py"
    inner.write_text(body.format(marker=str(marker)))
    log = tmp_path / "pytest.log"
    with open(log, "w") as out:
        proc = subprocess.Popen([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "conftest",
                                 "--basetemp", str(tmp_path / "base"), str(inner)],
                                cwd=TESTS, stdout=out, stderr=subprocess.STDOUT, start_new_session=True,
                                preexec_fn=_default_sigint)
    try:
        deadline = time.monotonic() + 120
        while len(_session(proc.pid)) < 3 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.2)  # pytest and its two workers
        time.sleep(1.0)
        assert proc.poll() is None and len(_session(proc.pid)) >= 3, log.read_text()[-2000:]
        (os.killpg if group else os.kill)(proc.pid, getattr(signal, sig))
        sent = time.monotonic()
        try:
            code = proc.wait(30)
        except subprocess.TimeoutExpired:
            code = None
        took = time.monotonic() - sent
        text = log.read_text()
        assert code == 2 and took < 10, (code, took, text[-2000:])  # pytest's 'interrupted', promptly
        assert "KeyboardInterrupt" in text and not marker.exists(), text[-2000:]
        end = time.monotonic() + 5
        while _session(proc.pid) and time.monotonic() < end:
            time.sleep(0.2)
        assert _session(proc.pid) == []  # no worker outlived pytest
    finally:
        if proc.poll() is None or _session(proc.pid):
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        proc.wait()
