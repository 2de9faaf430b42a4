"""wallcli scan: many videos through one decode each, on a Dask LocalCluster or a scheduler
started here (127.0.0.1 only, stopped here), into resumable JSON Lines or CSV."""
from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

# small, short simulated clips: a window (8.5 s) fits, a decode takes a fraction of a second
SIM = ["--size", "64x48", "--duration", "10.5", "--fps", "30", "--grid", "16x16", "--crf", "12"]
CLIPS = {"a.mp4": ["--people", "1", "--activity", "walking", "--seed", "1"],
         "sub/b.mp4": ["--people", "2", "--activity", "walking,jumping", "--seed", "2"],
         "sub/c.mp4": ["--people", "0", "--seed", "3"]}
TASKS = ("count", "activity", "snr")


def _main(*args) -> tuple[int, str]:
    from wallcli.cli.app import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        try:
            main([str(a) for a in args])
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 0
    return code, out.getvalue()


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """Three simulated clips (their .json ground truth beside them), one corrupt 'video' and a
    text file, in a folder with a subfolder."""
    root = tmp_path_factory.mktemp("scan") / "clips"
    (root / "sub").mkdir(parents=True)
    for name, spec in CLIPS.items():
        assert _main("simulate", "-o", root / name, *spec, *SIM)[0] == 0
    (root / "sub" / "broken.mp4").write_bytes((root / "a.mp4").read_bytes()[:3000])  # cut inside its header
    (root / "notes.txt").write_text("not a video\n")
    return root


@pytest.fixture(scope="module")
def single(folder) -> dict:
    """What the single-video commands answer for each clip: {(clip, task): --json object}."""
    out = {}
    for name in CLIPS:
        for task in TASKS:
            code, text = _main(task, folder / name, "--json")
            assert code == 0
            out[name, task] = json.loads(text)
    return out


def _lines(path: Path) -> list[dict]:
    return [json.loads(s) for s in path.read_text().splitlines()]


def _by_input(lines: list[dict], root: Path) -> dict:
    return {str(Path(d["input"]).relative_to(root)): d for d in lines}


@pytest.mark.slow
def test_scan_answers_what_the_single_video_commands_answer(folder, single, tmp_path, run_cli):
    out = tmp_path / "results.jsonl"
    code, stdout, err = run_cli("scan", folder, "-o", out, "--workers", "2", "--json")
    assert code == 0, err
    summary = json.loads(stdout)
    assert (summary["videos"], summary["ok"], summary["failed"], summary["skipped"]) == (4, 3, 1, 0)
    assert summary["hours"] == pytest.approx(3 * 10.5 / 3600, rel=1e-3)
    lines = _by_input(_lines(out), folder)
    assert sorted(lines) == sorted([*CLIPS, "sub/broken.mp4"])  # no sidecar .json, no notes.txt
    for name in CLIPS:
        line = lines[name]
        assert line["error"] is None and line["frames"] == 315 and line["duration"] == pytest.approx(10.5)
        assert line["size"] == (folder / name).stat().st_size and len(line["sha256"]) == 64
        for task in ("count", "activity"):
            want = single[name, task]
            got = line[task]
            assert "windows" not in got  # only with --windows
            assert got["label"] == want["label"]
            assert got["probabilities"] == pytest.approx(want["probabilities"], abs=1e-6)
            assert {k: v for k, v in got.items() if k != "probabilities"} == \
                {k: v for k, v in want.items() if k not in ("probabilities", "windows")}
        want = single[name, "snr"]
        assert line["snr"]["roi"] == want["roi"] and line["snr"]["frames"] == want["frames"] == 315
        for k in ("signal_power", "noise_power", "snr_db"):
            assert np.allclose(line["snr"][k], want[k], rtol=1e-9, atol=1e-12)
    bad = lines["sub/broken.mp4"]
    assert bad["error"] and "\n" not in bad["error"] and "broken.mp4" in bad["error"]
    assert not set(TASKS) & set(bad)
    assert "failed:" in err and "broken.mp4" in err


def test_csv_output_with_windows(folder, single, tmp_path, run_cli):
    out = tmp_path / "results.csv"
    code, _, err = run_cli("scan", folder / "a.mp4", folder / "sub", "-o", out, "--task", "snr,count",
                           "--windows", "--workers", "1")
    assert code == 0, err
    with open(out, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 4
    assert "activity.label" not in rows[0] and "count.probabilities.2" in rows[0] and "snr.snr_db.g" in rows[0]
    rows = {str(Path(r["input"]).relative_to(folder)): r for r in rows}
    for name in CLIPS:
        r, want = rows[name], single[name, "count"]
        assert r["error"] == "" and r["tasks"] == "count,snr"
        assert int(r["count.label"]) == want["label"]
        assert [float(r[f"count.probabilities.{c}"]) for c in want["classes"]] == \
            pytest.approx(want["probabilities"], abs=1e-6)
        assert [w["start"] for w in json.loads(r["count.windows"])] == [w["start"] for w in want["windows"]]
        assert float(r["snr.snr_db.r"]) == pytest.approx(single[name, "snr"]["snr_db"][0], abs=1e-9)
    assert rows["sub/broken.mp4"]["error"] and rows["sub/broken.mp4"]["count.label"] == ""


def _children(pid: int) -> list:
    import psutil

    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


@pytest.mark.slow
def test_resume_after_a_kill_loses_and_repeats_nothing(folder, tmp_path, run_cli):
    import psutil

    videos = tmp_path / "videos"
    videos.mkdir()
    for i in range(8):  # enough work that the kill lands midway
        shutil.copy(folder / "a.mp4", videos / f"v{i}.mp4")
    shutil.copy(folder / "sub" / "broken.mp4", videos / "broken.mp4")
    out = tmp_path / "r.jsonl"
    proc = subprocess.Popen([sys.executable, "-m", "wallcli", "scan", str(videos), "-o", str(out), "--workers", "1"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    kids = []
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            kids = _children(proc.pid) or kids
            if out.exists() and sum(d["error"] is None for d in _lines(out)) >= 2:
                break
            time.sleep(0.02)
        assert proc.poll() is None, f"the scan ended before it could be killed: {proc.stderr.read()}"
        proc.send_signal(signal.SIGKILL)  # a crash: no clean-up of any kind
        proc.wait(timeout=30)
        _, alive = psutil.wait_procs(kids, timeout=20)
        assert not alive, "Dask's worker processes outlived the killed scan"
    finally:
        if proc.poll() is None:
            proc.kill()
        for p in _children(proc.pid) + kids:
            with contextlib.suppress(psutil.NoSuchProcess):
                p.kill()
    before = out.read_text().splitlines()
    done = [s for s in before if json.loads(s)["error"] is None]
    assert 2 <= len(done) < 8
    with open(out, "a") as fh:  # what a kill in the middle of a write would leave
        fh.write('{"input": "' + str(videos / "v7.mp4"))

    code, stdout, err = run_cli("scan", videos, "-o", out, "--workers", "2", "--json")
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["skipped"] == len(done) and summary["processed"] == 9 - len(done)
    after = out.read_text().splitlines()
    assert after[:len(done)] == done  # finished lines kept byte for byte, the torn one gone
    inputs = [json.loads(s)["input"] for s in after]
    assert sorted(inputs) == sorted(str(p) for p in videos.iterdir())  # every video exactly once
    assert sum(json.loads(s)["error"] is not None for s in after) == 1


def test_resume_refuses_other_tasks_and_force_starts_again(folder, tmp_path, run_cli):
    out = tmp_path / "r.jsonl"
    assert run_cli("scan", folder / "a.mp4", "-o", out, "--task", "snr", "--workers", "1")[0] == 0
    first = out.read_text()
    code, _, err = run_cli("scan", folder / "a.mp4", "-o", out, "--task", "count", "--workers", "1")
    assert code == 1 and err.startswith("Error:") and "--task snr" in err and out.read_text() == first
    code, stdout, err = run_cli("scan", folder / "a.mp4", "-o", out, "--task", "snr", "--json")
    assert code == 0 and json.loads(stdout)["skipped"] == 1 and out.read_text() == first  # nothing to do: no cluster
    code, _, err = run_cli("scan", folder / "a.mp4", "-o", out, "--task", "count", "--force", "--workers", "1")
    assert code == 0, err
    (line,) = _lines(out)
    assert line["tasks"] == ["count"] and "count" in line and "snr" not in line


@pytest.mark.parametrize("args,code,words", [
    ([], 1, "no videos found"),
    (["--glob", "*.avi"], 1, "*.avi"),
    (["--task", "count,colour"], 2, "--task"),
])
def test_nothing_to_scan(tmp_path, run_cli, args, code, words):
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "readme.txt").write_text("no videos here")
    target = empty if "--glob" not in args else Path(__file__).parent / "golden"
    got, out, err = run_cli("scan", target, "-o", tmp_path / "r.jsonl", *args)
    assert got == code and out == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith("Error:") and words in err
    assert not (tmp_path / "r.jsonl").exists()


def _wait_for(path: Path, proc, seconds: float = 60) -> None:
    deadline = time.monotonic() + seconds
    while not path.exists():
        assert proc.poll() is None and time.monotonic() < deadline, "the Dask process did not start"
        time.sleep(0.1)


@pytest.mark.slow
def test_scheduler_runs_the_same_tasks_and_checks_its_workers(folder, single, tmp_path, run_cli):
    sfile = tmp_path / "scheduler.json"
    dask = [sys.executable, "-m", "dask"]
    procs = []
    try:
        procs.append(subprocess.Popen([*dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                       "--scheduler-file", str(sfile)], stderr=subprocess.DEVNULL))
        _wait_for(sfile, procs[0])
        address = json.loads(sfile.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        worker = [*dask, "worker", address, "--host", "127.0.0.1", "--nthreads", "1", "--no-dashboard"]
        procs.append(subprocess.Popen(worker, stderr=subprocess.DEVNULL))
        out = tmp_path / "r.jsonl"
        code, stdout, err = run_cli("scan", folder / "a.mp4", folder / "sub" / "c.mp4", "-o", out,
                                    "--scheduler", address, "--json")
        assert code == 0, err
        assert json.loads(stdout)["engine"] == address
        for line in _lines(out):
            name = str(Path(line["input"]).relative_to(folder))
            assert line["count"]["label"] == single[name, "count"]["label"]
            assert line["activity"]["probabilities"] == pytest.approx(single[name, "activity"]["probabilities"], abs=1e-6)

        # a worker with another wallcli: the scan must refuse before any work, naming both
        preload = tmp_path / "older_wallcli.py"
        preload.write_text("import wallcli\nwallcli.__version__ = '0.0.1-old'\n")
        procs.append(subprocess.Popen([*worker, "--preload", str(preload)], stderr=subprocess.DEVNULL))
        out2 = tmp_path / "r2.jsonl"
        deadline = time.monotonic() + 60
        while True:  # until the second worker has joined
            code, _, err = run_cli("scan", folder / "a.mp4", "-o", out2, "--scheduler", address)
            if code or time.monotonic() > deadline:
                break
            out2.unlink()
        from wallcli import __version__
        assert code == 1 and "0.0.1-old" in err and f"wallcli {__version__}" in err, err
        assert len(err.strip().splitlines()) == 1
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()


# ------------------------------------------------------------------------------ engine, watchdog
def _dies_on_bad(item: str, marks: str) -> str:
    """A task that kills its worker process on 'bad' (counting its tries in files)."""
    import os as _os
    from pathlib import Path as _Path

    if item == "bad":
        n = len(list(_Path(marks).iterdir()))
        (_Path(marks) / f"try{n}").write_text("")
        _os._exit(1)
    return item.upper()


def test_a_task_that_kills_its_worker_is_retried_once_then_reported(tmp_path):
    import cloudpickle

    from wallcli.batch.engine import Engine

    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # the workers cannot import this file
    try:
        with Engine(workers=1) as engine:
            got = dict(engine.map(_dies_on_bad, ["a", "bad", "b"], str(tmp_path),
                                  failed=lambda item, msg: f"failed: {msg}"))
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])
    assert got["a"] == "A" and got["b"] == "B"
    assert got["bad"].startswith("failed:") and "died" in got["bad"]
    assert len(list(tmp_path.iterdir())) == 2  # tried twice


def test_watchdog_gives_up_on_a_stalled_task_not_on_a_slow_one():
    import threading

    from wallcli.batch.task import Stalled, run_with_watchdog

    never = threading.Event()
    t0 = time.monotonic()
    with pytest.raises(Stalled):
        run_with_watchdog(lambda beat: never.wait(), timeout=0.3)
    assert time.monotonic() - t0 < 10

    def slow(beat):
        for _ in range(8):
            time.sleep(0.1)
            beat()
        return "done"

    assert run_with_watchdog(slow, timeout=0.5) == "done"
    with pytest.raises(ValueError):
        run_with_watchdog(lambda beat: int("x"), timeout=5)
    never.set()


def test_scans_snr_object_is_snr_json_verdict_included(tmp_path, run_cli):
    # scan --help: the answers equal those of 'wallcli snr --json'; one function builds both
    clip = Path(__file__).resolve().parents[1] / "examples" / "two-mixed.mp4"
    out = tmp_path / "day.jsonl"
    code, _, err = run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1")
    assert code == 0, err
    (line,) = _lines(out)
    code, stdout, err = run_cli("snr", clip, "--json")
    assert code == 0, err
    want = json.loads(stdout)
    assert line["snr"]["verdict"] == want["verdict"]
    assert set(want["verdict"]) == {"signal", "block", "snr_db", "text", "why"}
    assert sorted(line["snr"]) == sorted(want)
