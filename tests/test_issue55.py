"""Issue 55 (reliability, 5th round): one regression test (or a few) per item, on clips made here."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from clips import write_clip


def _wall(i, h=24, w=32):
    return np.full((h, w, 3), 120.0) + np.random.default_rng(i).normal(0, 1.0, (h, w, 3))


@pytest.fixture
def clip(tmp_path):
    return write_clip(tmp_path / "c.mkv", _wall, 12, fps=30, codec="ffv1", pix_fmt="bgr0", options={})


def _one_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error:") and "Traceback" not in err, err
    return lines[0]


# 1 ------------------------------------------------------- scan --force keeps the old results
@pytest.mark.parametrize("name", ["keep.jsonl", "keep.csv"])
def test_scan_force_that_fails_before_a_line_leaves_the_old_results(tmp_path, run_cli, clip, name):
    out = tmp_path / name
    out.write_text("old results, a line per video\n")  # --force does not read them
    code, stdout, err = run_cli("scan", clip, "-o", out, "--force", "--scheduler", "tcp://127.0.0.1:1")
    assert code == 1 and stdout == "" and "127.0.0.1:1" in _one_error(err)
    assert out.read_text() == "old results, a line per video\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["c.mkv", name])


# 2 ------------------------------------------- a short write to stdout is an error, -u or not
@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_FSIZE emulates a nearly full disk")
@pytest.mark.parametrize("unbuffered", ["1", ""])
def test_stdout_cut_short_by_a_full_disk_fails_even_unbuffered(tmp_path, unbuffered):
    import resource

    from clips import write_plot

    plot = write_plot(tmp_path / "p.npz", seconds=20)
    out = tmp_path / "o.json"

    def small_disk():  # the file may grow to 200 bytes: the first write is cut short, the next fails
        resource.setrlimit(resource.RLIMIT_FSIZE, (200, 200))

    env = {**os.environ, "PYTHONUNBUFFERED": unbuffered}
    with open(out, "wb") as f:
        run = subprocess.run([sys.executable, "-m", "wallcli", "count", str(plot), "--json"], stdout=f,
                             stderr=subprocess.PIPE, preexec_fn=small_disk, env=env, timeout=120)
    assert run.returncode == 1 and out.stat().st_size == 200
    assert "cannot write to stdout" in _one_error(run.stderr.decode())


# 3 ------------------------------------------------------------ amplify keeps the source's times
def _times(path) -> list[float]:
    import av

    with av.open(str(path)) as c:
        return [float(f.pts * f.time_base) for f in c.decode(video=0)]


@pytest.mark.parametrize("case", ["gap", "10fps", "vfr"])
def test_amplify_output_frames_keep_their_source_times(tmp_path, run_cli, case):
    if case == "gap":  # 3 s at 30 fps, 2 s of frames missing, 3 s more
        n, fps, tb = 180, 30, Fraction(1, 30)
        pts = lambda i: i if i < 90 else i + 60  # noqa: E731
    elif case == "10fps":  # the stream says 30 fps, its frames are 0.1 s apart
        n, fps, tb = 40, 30, Fraction(1, 30)
        pts = lambda i: 3 * i  # noqa: E731
    else:  # a phone's variable rate: intervals of 1/30 and 1/15 s, in a 1/1000 s time base
        n, fps, tb = 90, 30, Fraction(1, 1000)
        pts = lambda i: round(1000 * (i / 30 + (i // 2) / 30))  # noqa: E731
    src = write_clip(tmp_path / "src.mkv", lambda i: _wall(i, 48, 64), n, fps=fps, codec="ffv1", pix_fmt="bgr0",
                     options={}, pts_fn=pts, time_base=tb)
    code, _, err = run_cli("amplify", src, tmp_path / "amp.mp4", "--gain", "10")
    assert code == 0, err
    want, got = _times(src), _times(tmp_path / "amp.mp4")
    assert len(got) == len(want) == n
    assert np.allclose(np.array(got) - got[0], np.array(want) - want[0], atol=0.002), (got[-1], want[-1])
