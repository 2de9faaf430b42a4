"""`wallcli simulate` end to end: video + sidecar + preview, determinism, usage errors."""

import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

from wallcli.io.video import open_video

FAST = ["--size", "64x48", "--duration", "0.6", "--fps", "15", "--grid", "8x8"]


def _decode(path):
    with open_video(path) as r:
        return np.stack([f.planes.rgb() for f in r.frames()])


def test_simulate_writes_video_sidecar_preview_and_is_deterministic(tmp_path, run_cli):
    a, b = tmp_path / "a.mkv", tmp_path / "b.mkv"
    code, out, err = run_cli("simulate", "-o", a, "--people", "2", "--activity", "walking,crouching",
                             "--seed", "7", "--preview", tmp_path / "p.png", "--json", *FAST)
    assert code == 0, err
    assert json.loads(out)["people"] == 2
    truth = json.loads(a.with_suffix(".json").read_text())
    assert {k: truth[k] for k in ("people", "activity", "fps", "frames", "seed")} == \
        {"people": 2, "activity": "walking", "fps": 15.0, "frames": 9, "seed": 7}
    assert [len(p["positions"]) for p in truth["persons"]] == [9, 9]
    assert (tmp_path / "p.png").stat().st_size > 10_000
    code, out, err = run_cli("simulate", "-o", b, "--people", "2", "--activity", "walking,crouching", "--seed", "7", *FAST)
    assert code == 0, err
    assert out == ""  # stdout carries data only, and none was asked for
    fa, fb = _decode(a), _decode(b)
    assert fa.shape == (9, 48, 64, 3)
    np.testing.assert_array_equal(fa, fb)
    code, _, err = run_cli("simulate", "-o", a, *FAST)  # exists, no --force
    assert code == 1 and err.startswith("Error:")


def test_simulate_flatland_mp4(tmp_path, run_cli):
    out = tmp_path / "f.mp4"
    code, _, err = run_cli("simulate", "-o", out, "--world", "flatland", "--people", "1", *FAST)
    assert code == 0, err
    assert json.loads(out.with_suffix(".json").read_text())["people"] == 1


@pytest.mark.parametrize("args", [["--activity", "dancing"], ["--size", "65x48"], ["--distance", "2,1"],
                                  ["--world", "mars"], ["--dataset", "4", "--task", "sing"], ["--people", "3"]])
def test_simulate_usage_errors_exit_2(tmp_path, run_cli, args):
    code, _, err = run_cli("simulate", "-o", tmp_path / "x.mp4", *args)
    assert code == 2 and "Error:" in err


@pytest.mark.skipif(shutil.which("taskset") is None or len(os.sched_getaffinity(0)) < 2,
                    reason="needs taskset and two CPUs")
def test_simulated_h264_does_not_depend_on_the_number_of_cores(tmp_path):
    """x264's output changes with its thread count, and FFmpeg's default is one per core: the
    same seed must give the same file on a laptop and on a 64-core server (docs/contract.md)."""
    args = [sys.executable, "-m", "wallcli", "simulate", "--people", "1", "--seed", "3", "--duration", "1",
            "--size", "640x360"]
    one, all_ = tmp_path / "one.mp4", tmp_path / "all.mp4"
    subprocess.run(["taskset", "-c", str(min(os.sched_getaffinity(0))), *args, "-o", str(one)], check=True,
                   capture_output=True)
    subprocess.run([*args, "-o", str(all_)], check=True, capture_output=True)
    assert one.read_bytes() == all_.read_bytes()


@pytest.mark.parametrize("suffix", [".mkv", ".y4m"])
def test_crf_is_refused_where_it_would_not_apply(tmp_path, run_cli, suffix):
    """Issue 38 item 11: .mkv is lossless FFV1 whatever --crf said (and the sidecar said crf 30)."""
    out = tmp_path / f"x{suffix}"
    code, _, err = run_cli("simulate", "-o", out, "--crf", "30", "--size", "32x32", "--duration", "0.4",
                           "--fps", "15", "--grid", "4x4")
    assert code == 2 and "--crf" in err and suffix in err
    assert list(tmp_path.iterdir()) == []
    code, _, err = run_cli("simulate", "-o", out, "--size", "32x32", "--duration", "0.4", "--fps", "15",
                           "--grid", "4x4")
    assert code == 0, err


def test_simulate_shows_a_progress_bar_on_a_terminal_only(tmp_path, run_cli, monkeypatch):
    import io
    import re

    from rich.console import Console

    import wallcli.cli.output as output

    # stderr not a terminal (a pipe, a log file): not a character of a bar, only the 'wrote' line
    code, out, err = run_cli("simulate", "-o", tmp_path / "a.mkv", "--seed", "1", *FAST)
    assert code == 0 and out == "" and err.startswith("wrote ") and len(err.strip().splitlines()) == 1
    # stderr a terminal: the bar counts the frames rendered, on stderr (stdout untouched)
    term = io.StringIO()
    monkeypatch.setattr(output, "console_err", Console(file=term, force_terminal=True, width=100, highlight=False,
                                                       markup=False))
    code, out, err = run_cli("simulate", "-o", tmp_path / "b.mkv", "--seed", "1", *FAST)
    assert code == 0 and out == "", err
    shown = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", term.getvalue())
    assert "simulate" in shown and re.search(r"\b\d+/9\b", shown), shown[-400:]
    assert "wrote " in shown  # the line that names the files follows the bar
