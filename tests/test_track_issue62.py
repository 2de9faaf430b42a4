"""wallcli track, issue 62: a plot file's stored view verdict, frames lost, a followed file replaced."""
from __future__ import annotations

import json
from fractions import Fraction

import numpy as np
import pytest

from clips import write_clip
from test_track import FPS, _bounce, _plot
from wallcli.signal import track as tr


# ------------------------------------------------------------------- 3: the view stored in a .npz
def _pan(path, w=64, h=48, n=150):
    import cv2

    tex = cv2.GaussianBlur(np.random.default_rng(1).normal(128, 30, (200, 400, 3)), (0, 0), 2)
    return write_clip(path, lambda i: tex[50:50 + h, 10 + i:10 + i + w], n, fps=30, codec="rawvideo",
                      pix_fmt="yuv444p", options={})


def _view_shape(view):
    return {"usable", "issues", "reason", "notes", "gaps"} <= set(view) and "spans" not in view


def test_a_plot_of_a_panning_camera_carries_the_videos_verdict(tmp_path, run_cli):
    clip = _pan(tmp_path / "pan.nut", n=300)  # long enough for one count window
    npz = tmp_path / "pan.npz"
    assert run_cli("stplot", str(clip), "-o", str(npz))[0] == 0
    code, out, err = run_cli("track", str(clip), "--json")
    assert code == 0, err
    video = json.loads(out)
    code, out, err = run_cli("track", str(npz), "--json")
    assert code == 0, err
    plot = json.loads(out)
    assert video["view"]["usable"] is False and "camera motion" in video["view"]["issues"]
    # one view block, one meaning: the .npz's is the video's (and count's on the same file)
    assert _view_shape(plot["view"]) and plot["view"]["usable"] is False
    assert plot["view"]["issues"] == video["view"]["issues"]
    assert plot["reason"].startswith("view not usable") and "camera motion" in plot["reason"]
    code, out, err = run_cli("count", str(npz), "--json")
    assert json.loads(out)["view"]["usable"] == plot["view"]["usable"]
    code, out, err = run_cli("track", str(npz), "--strict")
    assert code == 1 and "camera motion" in err


def test_a_plot_of_a_tiny_region_says_too_small_to_check(tmp_path, run_cli):
    clip = _pan(tmp_path / "still.nut", n=90)
    npz = tmp_path / "tiny.npz"
    assert run_cli("stplot", str(clip), "--roi", "10,10,2,2", "-o", str(npz))[0] == 0
    code, out, err = run_cli("track", str(npz), "--json")
    assert code == 0, err
    res = json.loads(out)
    assert _view_shape(res["view"]) and res["view"]["usable"] is False
    assert "too small to check" in res["view"]["issues"]
    assert "too small to check" in res["reason"] and "nobody moves" not in res["reason"]


# ------------------------------------------------------------------- 5: frames lost
def test_rows_either_side_of_a_jump_are_never_one_track():
    walk = _bounce(8.0)
    rows, t = _plot(14, [walk], seed=11)
    for lost in (2.03, 10.0):
        times = t + lost * (t > 2.97)
        tracks = tr.track_rows(rows, times, FPS)
        assert tracks
        for k in tracks:
            ts = np.array(k.t)
            assert not ((ts < 3.0).any() and (ts > 2.97 + lost).any()), (lost, k.t[0], k.t[-1])
            assert not ((ts > 2.97 + 1e-6) & (ts < 2.97 + lost)).any()


def test_given_gaps_drop_interpolated_rows_and_end_tracks():
    walk = _bounce(8.0)
    rows, t = _plot(12, [walk], seed=12)
    tracks = tr.track_rows(rows, t, FPS, gaps=[(2.97, 5.0)])
    assert len(tracks) >= 2
    for k in tracks:
        ts = np.array(k.t)
        assert not ((ts > 2.97 + 1e-6) & (ts < 5.0 - 1e-6)).any()
        assert ts[-1] <= 2.97 + 1e-6 or ts[0] >= 5.0 - 1e-6


def _gappy(path, lost):
    """A walker's wall, 30 fps, with ``lost`` seconds of frames missing after 2.97 s."""
    w, h = 96, 72
    xs = np.arange(w) + 0.5
    rng = np.random.default_rng(2)
    walk = _bounce(6.0, 0.15, 0.85)
    times = [i / 30 + lost * (i > 89) for i in range(330)]

    def frame(i):
        img = np.full((h, w), 120.0) - 3.0 * np.exp(-0.5 * ((xs - walk(times[i]) * w) / 8.0) ** 2)[None, :]
        return np.repeat((img + rng.normal(0, 1.0, img.shape))[:, :, None], 3, axis=2)

    return write_clip(path, frame, len(times), codec="libx264", pix_fmt="yuv444p", fmt="matroska",
                      options={"crf": "0", "preset": "ultrafast"}, time_base=Fraction(1, 1000),
                      pts_fn=lambda i: round(times[i] * 1000))


@pytest.mark.parametrize("lost", [2.03, 10.0])
def test_no_sample_where_no_frame_is_and_no_track_across_a_gap(tmp_path, run_cli, lost):
    clip = _gappy(tmp_path / f"gap{lost}.mkv", lost)
    code, out, err = run_cli("track", str(clip), "--json")
    assert code == 0, err
    res = json.loads(out)
    assert res["tracks"], res["reason"]
    a, b = 89 / 30, 90 / 30 + lost
    for k in res["tracks"]:
        ts = np.array([s["t"] for s in k["samples"]])
        assert not ((ts > a + 1e-3) & (ts < b - 1e-3)).any(), (k["start"], k["end"])
        assert not ((ts <= a + 1e-3).any() and (ts >= b - 1e-3).any())


# ------------------------------------------------------------------- 6: a followed file replaced
def _opened(pid: int, path) -> bool:
    import os

    try:
        return any(os.path.realpath(f"/proc/{pid}/fd/{fd}") == str(path) for fd in os.listdir(f"/proc/{pid}/fd"))
    except OSError:
        return False


@pytest.mark.parametrize("how", ["random", "shrink"])
def test_follow_says_a_file_truncated_or_overwritten_and_exits_1(tmp_path, how):
    import subprocess
    import sys
    import time

    clip = _gappy(tmp_path / "rec.mkv", 0.0)
    size = clip.stat().st_size
    proc = subprocess.Popen([sys.executable, "-m", "wallcli", "track", str(clip), "--follow", "--idle-timeout", "8"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not _opened(proc.pid, clip.resolve()) and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        time.sleep(1.0)
        with open(clip, "r+b") as fh:  # in place, as a recorder restarting on the same name would
            fh.truncate(0)
            fh.write(np.random.default_rng(0).bytes(size if how == "random" else 2000))
        out, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    lines = err.strip().splitlines()
    assert proc.returncode == 1, err
    assert lines[-1].startswith("Error:") and ("shrank" in lines[-1] or "replaced" in lines[-1]), err
    assert "Traceback" not in err


def test_the_reports_tracks_end_at_a_gap_too(tmp_path):
    from wallcli.report.analysis import analyse, load_models

    a = analyse(str(_gappy(tmp_path / "gap.mkv", 2.03)), models=load_models())
    assert a.tracks["tracks"]
    for k in a.tracks["tracks"]:
        ts = np.array([s["t"] for s in k["samples"]])
        assert not ((ts > 89 / 30 + 1e-3) & (ts < 5.0 - 1e-3)).any()
