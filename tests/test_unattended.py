"""Issue 29: ways an unattended batch died or lied, one regression test (or a few) per defect.
(Its items 10 and 11 are evaluate's, tested with evaluate.) Servers and clusters listen on
127.0.0.1 only and are stopped here."""
from __future__ import annotations

import contextlib
import csv
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from clips import one_error, simulated_walk, tiny_clip, write_plot

WALLCLI = [sys.executable, "-m", "wallcli"]


@pytest.fixture(scope="module")
def video(tmp_path_factory) -> Path:
    """One short simulated clip (a window fits; a decode takes a fraction of a second)."""
    return simulated_walk(tmp_path_factory.mktemp("video") / "walk.mp4")


@pytest.fixture
def clip(tmp_path):
    """A tiny clip for the commands that fail before they decode."""
    return tiny_clip(tmp_path / "c.mkv")


def _one_error(err: str) -> str:
    line = one_error(err)
    assert "internal error" not in line, line  # a clean line says what is wrong
    return line


def _copies(folder: Path, video: Path, names) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        shutil.copy(video, os.path.join(os.fsencode(folder), os.fsencode(name)))
    return folder


def _lines(path: Path) -> list[dict]:
    return [json.loads(s) for s in path.read_text(encoding="utf-8").splitlines()]


def _temporaries(folder: Path) -> list[str]:
    return [p.name for p in folder.iterdir() if ".tmp" in p.name]


def _limited(limit_bytes: int):
    def apply():
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))
    return apply


# 1 ------------------------------------------------------------------- outputs that are not files
@pytest.mark.parametrize("target", ["/dev/full", "/dev/zero", "/dev/null", "fifo"])
def test_scan_refuses_an_output_that_is_not_a_file_before_reading_it(tmp_path, video, target):
    if target == "fifo":
        target = str(tmp_path / "fifo.jsonl")
        os.mkfifo(target)
    elif not os.path.exists(target):
        pytest.skip(f"no {target} here")
    folder = _copies(tmp_path / "v", video, ["a.mp4"])
    # in a process of its own, with its memory bounded: before, /dev/zero was read as earlier
    # results without end, /dev/full too, and a FIFO waited for a writer for ever
    res = subprocess.run([*WALLCLI, "scan", str(folder), "-o", target, "--workers", "1"], capture_output=True,
                         text=True, timeout=120, preexec_fn=_limited(3 << 30))
    line = _one_error(res.stderr)
    assert res.returncode == 1 and ("is a device" in line or "named pipe" in line) and target in line


def test_other_commands_refuse_a_fifo_output_even_with_force(tmp_path, clip, run_cli):
    fifo = tmp_path / "p.npz"
    os.mkfifo(fifo)
    code, out, err = run_cli("stplot", clip, "-o", fifo, "--force")
    assert code == 1 and out == "" and "named pipe" in _one_error(err)
    assert Path(fifo).is_fifo()


# 2 -------------------------------------------------------------------------- symbolic link loops
def test_a_symlink_loop_among_the_videos_is_that_videos_error_line(tmp_path, video, run_cli):
    folder = _copies(tmp_path / "v", video, ["good.mp4"])
    os.symlink("loop.mp4", folder / "loop.mp4")  # points at itself
    out = tmp_path / "r.jsonl"
    code, _, err = run_cli("scan", folder, "-o", out, "--workers", "1")
    assert code == 0, err
    lines = {Path(d["input"]).name: d for d in _lines(out)}
    assert lines["good.mp4"]["error"] is None and lines["good.mp4"]["count"]["label"] in (0, 1, 2)
    assert "symbolic link" in lines["loop.mp4"]["error"]


@pytest.mark.parametrize("command", [["report", "{loop}", "-o", "{tmp}/x.html"], ["stplot", "{loop}", "-o", "{tmp}/x.npz"],
                                     ["amplify", "{loop}", "{tmp}/x.mp4"], ["snr", "{loop}"]])
def test_a_symlink_loop_as_the_input_is_one_clean_error(tmp_path, run_cli, command):
    loop = tmp_path / "loop.mp4"
    os.symlink(loop.name, loop)
    code, out, err = run_cli(*(a.format(loop=loop, tmp=tmp_path) for a in command))
    assert code == 1 and out == "" and "symbolic link" in _one_error(err)


@pytest.mark.parametrize("command", [["stplot", "{clip}", "-o", "{loop}.npz"], ["stplot", "{clip}", "-o", "{loop}.npz", "--force"],
                                     ["report", "{clip}", "-o", "{loop}.html"], ["scan", "{clip}", "-o", "{loop}.jsonl"]])
def test_a_symlink_loop_as_the_output_is_one_clean_error(tmp_path, clip, run_cli, command):
    args = [a.format(clip=clip, loop=tmp_path / "loop") for a in command]
    out_path = Path(args[args.index("-o") + 1])
    os.symlink(out_path.name, out_path)
    code, out, err = run_cli(*args)
    assert code == 1 and out == "" and "symbolic link loop" in _one_error(err)
    assert out_path.is_symlink() and _temporaries(tmp_path) == []


# 3 ------------------------------------------------------------------------- non-UTF-8 file names
BAD = os.fsdecode(b"bad\xff\xfename.mp4")
needs_bytes = pytest.mark.skipif(BAD == "bad\ufffd\ufffdname.mp4", reason="file names here cannot hold undecodable bytes")


@needs_bytes
def test_scan_csv_of_a_non_utf8_name_is_whole_and_resumes(tmp_path, video, run_cli):
    from wallcli.io.text import unescape_surrogates

    folder = _copies(tmp_path / "v", video, ["a.mp4", os.fsencode(BAD), "z.mp4"])
    out = tmp_path / "r.csv"
    code, _, err = run_cli("scan", folder, "-o", out, "--workers", "1")
    assert code == 0, err
    with open(out, newline="", encoding="utf-8") as fh:  # strict UTF-8
        rows = list(csv.DictReader(fh))
    assert [Path(unescape_surrogates(r["input"])).name for r in rows] == ["a.mp4", BAD, "z.mp4"]
    assert all(r["error"] == "" for r in rows)
    assert "bad\\udcff\\udcfename.mp4" in rows[1]["input"]  # escaped as in the JSON Lines
    before = out.read_bytes()
    code, stdout, err = run_cli("scan", folder, "-o", out, "--json")
    assert code == 0 and json.loads(stdout)["skipped"] == 3 and out.read_bytes() == before


@needs_bytes
def test_report_of_results_naming_a_non_utf8_file(tmp_path, run_cli):
    from wallcli.cli.output import to_json

    results = tmp_path / "r.jsonl"
    results.write_text(to_json({"input": BAD, "size": 10, "sha256": "0" * 64, "duration": 10.5, "frames": 315,
                                "tasks": ["snr"], "error": None}) + "\n" +
                       to_json({"input": "b" + BAD, "tasks": ["snr"], "error": f"{BAD} is not a readable video"}) + "\n")
    code, _, err = run_cli("report", results, "-o", tmp_path / "index.html")
    assert code == 0, err
    page = (tmp_path / "index.html").read_text(encoding="utf-8")
    assert page.count("bad\\udcff\\udcfename.mp4") >= 3


@needs_bytes
def test_report_of_a_clip_with_a_non_utf8_name(tmp_path, video, run_cli):
    clip = _copies(tmp_path / "v", video, [os.fsencode(BAD)]) / BAD
    code, _, err = run_cli("report", clip, "-o", tmp_path / "page.html")
    assert code == 0, err
    page = (tmp_path / "page.html").read_text(encoding="utf-8")
    assert "bad\\udcff\\udcfename.mp4" in page and page.count("data:image/png;base64,") >= 4


@needs_bytes
def test_figures_titled_with_a_non_utf8_name(tmp_path, run_cli):
    plot = write_plot(tmp_path / os.fsdecode(b"p\xfe.npz"))
    code, _, err = run_cli("count", plot, "--plot", tmp_path / "t.png")
    assert code == 0, err
    assert (tmp_path / "t.png").read_bytes().startswith(b"\x89PNG")


# 4 --------------------------------------------------------------------------- CSV quoting rules
HOSTILE = ["new\nline.mp4", "cr\rname.mp4", "crlf\r\nname.mp4", 'q"uo,te.mp4', "plain.mp4"]


def test_csv_records_read_back_whatever_the_names_hold(tmp_path):
    from wallcli.batch.results import csv_columns, csv_record, flatten, read

    columns = csv_columns(("snr",), {})
    names = HOSTILE + [os.fsdecode(b"b\xff.mp4")]
    lines = [{"input": n, "size": 7, "sha256": "0" * 64, "tasks": ["snr"], "error": "x\ny" if i else None}
             for i, n in enumerate(names)]
    text = csv_record(columns) + "".join(csv_record(flatten(d, columns)) for d in lines)
    path = tmp_path / "r.csv"
    path.write_text(text, encoding="utf-8")
    entries, torn = read(path, columns)
    assert [e.input for e in entries] == names and not torn
    assert [e.error for e in entries] == [None] + ["x\ny"] * (len(names) - 1)
    assert "".join(e.raw + "\n" for e in entries) == text[len(csv_record(columns)):]  # written back as they were
    # a kill while a record was written: the whole ones before it are kept, the torn one dropped,
    # also when the cut falls just after a newline inside a quoted name
    first = csv_record(columns) + csv_record(flatten(lines[0], columns))
    path.write_text(first + csv_record(flatten(lines[1], columns))[:3], encoding="utf-8")
    entries, torn = read(path, columns)
    assert [e.input for e in entries] == names[:1] and torn
    path.write_text(first[:first.index("line.mp4")], encoding="utf-8")  # cut just after the quoted newline
    entries, torn = read(path, columns)
    assert entries == [] and torn


def test_scan_csv_with_newlines_and_quotes_in_names_resumes(tmp_path, video, run_cli):
    folder = _copies(tmp_path / "v", video, HOSTILE[:4])
    out = tmp_path / "r.csv"
    code, _, err = run_cli("scan", folder, "-o", out, "--task", "snr", "--workers", "1")
    assert code == 0, err
    with open(out, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert sorted(Path(r["input"]).name for r in rows) == sorted(HOSTILE[:4])
    assert all(r["error"] == "" and r["snr.frames"] == "315" for r in rows)
    before = out.read_bytes()
    code, stdout, err = run_cli("scan", folder, "-o", out, "--task", "snr", "--json")
    assert code == 0, err
    assert json.loads(stdout)["skipped"] == 4 and out.read_bytes() == before


# 5 --------------------------------------------------------------------------------------- Ctrl-C
def _live(pgid: int) -> list[str]:
    ps = subprocess.run(["ps", "-o", "stat=,args=", "-g", str(pgid)], capture_output=True, text=True).stdout
    return [p for p in ps.splitlines() if p.strip() and not p.split()[0].startswith("Z")]  # zombies are not ours to reap


@pytest.mark.skipif(not hasattr(os, "killpg") or shutil.which("ps") is None, reason="needs process groups and ps")
@pytest.mark.parametrize("moment", ["start-up", "work"])
def test_ctrl_c_during_a_scan_is_one_line(tmp_path, video, moment):
    import psutil

    folder = _copies(tmp_path / "v", video, [f"v{i}.mp4" for i in range(6)])
    out = tmp_path / "r.jsonl"
    # a session of its own: the signal goes to the whole group, as a terminal's Ctrl-C does
    proc = subprocess.Popen([*WALLCLI, "scan", str(folder), "-o", str(out), "--workers", "2"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            if moment == "start-up":
                with contextlib.suppress(psutil.Error):
                    kids = [p for p in psutil.Process(proc.pid).children(recursive=True)
                            if "spawn_main" in " ".join(p.cmdline())]
                    if any(time.time() - p.create_time() > 0.5 for p in kids):  # a worker is importing
                        break
            elif out.exists() and out.read_text().count("\n") >= 1:
                break
            time.sleep(0.02)
        assert proc.poll() is None, f"the scan ended before the signal: {proc.stderr.read()}"
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
        assert proc.returncode == 1 and err == "Error: interrupted\n"
        deadline = time.monotonic() + 30
        while _live(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert _live(proc.pid) == []  # every worker went with it
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)


# 6 --------------------------------------------------------------------- not a Dask scheduler
SHORT_TIMEOUT = ("import sys, wallcli.batch.engine as e; e.CONNECT_TIMEOUT = 2.0\n"
                 "from wallcli.cli.entry import main\nmain()\n")


@contextlib.contextmanager
def _server(handler):
    """A TCP server on 127.0.0.1 (a free port) calling ``handler(conn)`` per connection; stopped at the end."""
    sock = socket.create_server(("127.0.0.1", 0))
    stop = threading.Event()

    def serve():
        sock.settimeout(0.2)
        while not stop.is_set():
            try:
                conn, _ = sock.accept()
            except (socket.timeout, OSError):
                continue
            threading.Thread(target=handler, args=(conn, stop), daemon=True).start()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{sock.getsockname()[1]}"
    finally:
        stop.set()
        thread.join(5)
        sock.close()


def _http(conn, stop):  # an HTTP server: waits for a request line that never ends
    with conn:
        conn.settimeout(0.2)
        while not stop.is_set():
            try:
                if not conn.recv(65536):
                    return
            except socket.timeout:
                continue
            except OSError:
                return


def _garbage(conn, stop):  # answers anything with bytes that are no Dask message
    with conn:
        with contextlib.suppress(OSError):
            conn.sendall(b"\xff" * 64 + b"HTTP/1.0 400 Bad Request\r\n\r\n" * 8)
            stop.wait(30)


@pytest.mark.parametrize("handler,words", [(_http, "did not answer as a Dask scheduler within 2 s"),
                                           (_garbage, "answered, but not as a Dask scheduler")])
def test_a_scheduler_address_that_is_no_dask_scheduler(tmp_path, clip, handler, words):
    out = tmp_path / "r.jsonl"
    with _server(handler) as address:
        t0 = time.monotonic()
        res = subprocess.run([sys.executable, "-c", SHORT_TIMEOUT, "scan", str(clip), "-o", str(out),
                              "--scheduler", address], capture_output=True, text=True, timeout=120,
                             preexec_fn=_limited(3 << 30))
    line = _one_error(res.stderr)
    assert res.returncode == 1 and address in line and words in line and "memory" not in line
    assert time.monotonic() - t0 < 60
    assert not out.exists()  # no empty results file left behind


def test_scan_help_states_the_scheduler_timeout(run_cli):
    from wallcli.batch.engine import CONNECT_TIMEOUT

    code, out, _ = run_cli("scan", "--help")
    assert code == 0 and f"time out after {CONNECT_TIMEOUT:g} s" in " ".join(out.split())


# 7 ----------------------------------------------------- outputs the file system cannot take
@pytest.mark.parametrize("name", ["n" * 245 + ".jsonl", "n" * 251 + ".npz", "é" * 124 + ".npz", "x." + "s" * 253])
def test_temporaries_of_long_names_fit_the_file_system(tmp_path, name):
    from wallcli.io.writer import atomic_path, name_max

    if len(os.fsencode(name)) > name_max(tmp_path):
        pytest.skip("this file system takes shorter names")
    with atomic_path(tmp_path / name) as tmp:
        assert len(os.fsencode(tmp.name)) <= name_max(tmp_path) and tmp.name.startswith(".")
        tmp.write_text("x")
    assert [p.name for p in tmp_path.iterdir()] == [name]


def test_stplot_to_a_245_character_name(tmp_path, clip, run_cli):
    out = tmp_path / ("p" * 241 + ".npz")
    code, _, err = run_cli("stplot", clip, "-o", out)
    assert code == 0, err
    assert out.exists() and _temporaries(tmp_path) == []
    code, _, err = run_cli("stplot", clip, "-o", tmp_path / ("p" * 300 + ".npz"))
    assert code == 1 and "bytes long" in _one_error(err)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux's /proc and /sys")
@pytest.mark.parametrize("out", ["/proc/wallcli-test.npz", "/sys/wallcli-test.npz"])
def test_outputs_under_proc_and_sys(clip, run_cli, out):
    code, stdout, err = run_cli("stplot", clip, "-o", out)
    assert code == 1 and stdout == "" and _one_error(err)


@contextlib.contextmanager
def _tmpfs(where: Path, options: str):
    where.mkdir()
    res = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(where)], capture_output=True)
    if res.returncode != 0:
        pytest.skip("cannot mount a file system here (needs root)")
    try:
        yield where
    finally:
        subprocess.run(["umount", str(where)], check=True)


@pytest.mark.skipif(shutil.which("mount") is None, reason="needs mount")
def test_read_only_and_full_file_systems(tmp_path, clip, run_cli):
    with _tmpfs(tmp_path / "ro", "ro,size=1m") as ro:
        for args in (["stplot", clip, "-o", ro / "p.npz"], ["simulate", "--dataset", "2", "--task", "count", "-o", ro / "ds"]):
            code, _, err = run_cli(*args)
            assert code == 1 and ("read-only" in _one_error(err) or "not writable" in err)
    with _tmpfs(tmp_path / "full", "size=64k") as full:
        (full / "fill").write_bytes(b"\0" * 60_000)
        code, _, err = run_cli("stplot", clip, "-o", full / "p.npz", "--png", full / "p.png", "--bins", "16")
        assert code == 1 and "no space left on device" in _one_error(err)
        assert sorted(p.name for p in full.iterdir()) == ["fill"]


# 8 --------------------------------------------------------------------- one scan per results file
def test_a_second_scan_of_one_results_file_stops_at_once(tmp_path, video, run_cli):
    folder = _copies(tmp_path / "v", video, [f"v{i}.mp4" for i in range(4)])
    out = tmp_path / "r.jsonl"
    first = subprocess.Popen([*WALLCLI, "scan", str(folder), "-o", str(out), "--workers", "1"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not out.exists() and first.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        code, _, err = run_cli("scan", folder, "-o", out, "--workers", "1")
        assert first.poll() is None, "the first scan ended too soon for this test"
        assert code == 1 and "another wallcli scan is writing" in _one_error(err)
        assert first.wait(timeout=300) == 0, first.stderr.read()
    finally:
        if first.poll() is None:
            first.kill()
    assert sorted(Path(d["input"]).name for d in _lines(out)) == [f"v{i}.mp4" for i in range(4)]  # each once


def test_report_counts_each_video_once(tmp_path, run_cli):
    from wallcli.cli.output import to_json

    lines = [to_json({"input": f"cam/{i}.mp4", "size": 10, "sha256": str(i) * 64, "duration": 10.0, "frames": 300,
                      "tasks": ["snr"], "error": None}) for i in range(3)]
    results = tmp_path / "r.jsonl"
    results.write_text("\n".join(lines + lines[:2] + ['{"input": "cam/0.mp4", "tasks": ["snr"], "error": "x"}']) + "\n")
    code, _, err = run_cli("report", results, "-o", tmp_path / "index.html")
    assert code == 0, err
    assert "2 videos appear on more than one line" in " ".join(err.split())
    import re

    page = (tmp_path / "index.html").read_text(encoding="utf-8")
    total = {k: int(v) for k, v in re.findall(r'id="total-(\w+)"[^>]*>(\d+)<', page)}
    assert total["videos"] == 3 and total["failed"] == 1  # cam/0's last line is its failure


# 9 -------------------------------------------------------- the results file among the videos
def test_rescanning_a_folder_that_holds_its_results_file_resumes(tmp_path, video, run_cli):
    folder = _copies(tmp_path / "gl", video, ["v.mp4"])
    out = folder / "res.jsonl"
    code, _, err = run_cli("scan", folder, "-o", out, "--glob", "*", "--workers", "1", "--task", "snr")
    assert code == 0, err
    before = out.read_bytes()
    code, stdout, err = run_cli("scan", folder, "-o", out, "--glob", "*", "--workers", "1", "--task", "snr", "--json")
    assert code == 0, err
    assert json.loads(stdout)["skipped"] == 1 and out.read_bytes() == before
    code, _, err = run_cli("scan", out, "-o", out)  # named as an input: that is a mistake, said so
    assert code == 1 and "is the input" in _one_error(err)


# 12 ------------------------------------------------------------------- workers that cannot start
NO_INTERPRETER = ("import multiprocessing, sys\nmultiprocessing.set_executable(sys.argv.pop(1))\n"
                  "from wallcli.cli.entry import main\nmain()\n")


@pytest.mark.parametrize("script,mode,words", [("not a program\n", 0o644, "permission denied"),
                                               ("#!/bin/sh\necho 'no licence here' >&2\nexit 3\n", 0o755,
                                                "exits at once: no licence here")])
def test_workers_that_cannot_start_are_one_clean_line(tmp_path, video, script, mode, words):
    python = tmp_path / "python"  # the interpreter the worker processes would run
    python.write_text(script)
    python.chmod(mode)
    out = tmp_path / "r.jsonl"
    res = subprocess.run([sys.executable, "-c", NO_INTERPRETER, str(python), "scan", str(video), "-o", str(out),
                          "--workers", "2"], capture_output=True, text=True, timeout=300)
    line = _one_error(res.stderr)
    assert res.returncode == 1 and "the local Dask cluster could not start" in line
    assert str(python) in line and words in line
    assert not out.exists()
