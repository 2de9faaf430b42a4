import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from clips import write_clip
from stplot_fixtures import streak_plot

from wallcli.errors import WallcliError
from wallcli.infer.classify import classify_plot, follow
from wallcli.infer.model import Model
from wallcli.signal.stplot import StPlot

WIN_S = 256 / 30


def _plot(fps, seconds, bins=64):
    h, v, t = streak_plot(fps, seconds, bins)
    return StPlot(h, v, t, np.zeros((bins, 3), np.float32), np.zeros((bins, 3), np.float32), {})


def _wall_frame(i, fps=30.0, h=48, w=64):
    """A grey wall with a faint shadow sweeping across it (a few code values)."""
    x = np.arange(w)
    pos = (8 + 12.0 * i / fps) % w
    shade = 6.0 * np.exp(-0.5 * ((x - pos) / 4.0) ** 2)
    img = np.full((h, w, 3), 120.0) - shade[None, :, None] * np.array([1.0, 0.8, 0.6])
    return img + np.random.default_rng(i).normal(0, 1.0, img.shape)


@pytest.mark.parametrize("task", ["count", "activity"])
def test_json_result_follows_the_contract(models, plot_file, run_cli, task):
    code, out, err = run_cli(task, plot_file(seconds=12.0), "--model", models[task], "--json")
    assert code == 0, err
    r = json.loads(out)
    classes = [0, 1, 2] if task == "count" else ["none", "walking", "crouching", "waving", "jumping"]
    assert r["task"] == task and r["classes"] == classes and r["fps"] == 30.0
    assert set(r["model"]) == {"name", "version", "sha256"} and r["model"]["name"] == f"test-{task}"
    assert abs(sum(r["probabilities"]) - 1) < 1e-6
    assert r["label"] == classes[int(np.argmax(r["probabilities"]))]
    w = r["windows"]
    # 360 samples at 30 fps, stride 64: starts 0, 64 and the end-aligned 104
    assert [round(x["start"] * 30) for x in w] == [0, 64, 104]
    assert w[0]["start"] == 0.0 and w[0]["end"] == pytest.approx(WIN_S, abs=1e-3)
    for x in w:
        assert x["label"] == classes[int(np.argmax(x["probabilities"]))]
        assert abs(sum(x["probabilities"]) - 1) < 1e-5
    if task == "activity":  # clip probabilities are the mean of the windows'
        assert np.allclose(np.mean([x["probabilities"] for x in w], axis=0), r["probabilities"], atol=1e-9)
    else:  # count, in two stages: each net's window mean, then combined (tests/infer/test_twostage.py)
        from wallcli.infer.twostage import combine

        pc = np.mean([x["stages"]["count"] for x in w], axis=0)
        pa = np.mean([x["stages"]["activity"] for x in w], axis=0)
        assert np.allclose(combine(pc[None], pa[None])[0], r["probabilities"], atol=1e-5)


@pytest.mark.parametrize("fps", [24.0, 25.0, 29.97, 60.0])
def test_ten_seconds_at_any_rate_gives_a_window(models, fps):
    r = classify_plot(Model.load(models["count"]), _plot(fps, 10.0), stride=64, source="x")
    assert len(r["windows"]) >= 1 and r["windows"][-1]["end"] <= 10.0 + 1e-6


@pytest.mark.parametrize("fps,seconds", [(30.0, 8.0), (60.0, 8.4)])
def test_too_short_clip_names_the_frames_needed(models, plot_file, run_cli, fps, seconds):
    code, out, err = run_cli("count", plot_file(fps=fps, seconds=seconds), "--model", models["count"], "--json")
    assert code == 1 and out == ""
    assert err.startswith("Error:") and "too short" in err and "needs 256 frames" in err


def test_plot_with_other_bins_is_refused(models, plot_file, run_cli):
    code, _, err = run_cli("activity", plot_file(bins=32), "--model", models["activity"])
    assert code == 1 and "32 bins" in err and "64" in err


def test_stride_option_and_table_output(models, plot_file, run_cli):
    code, out, err = run_cli("count", plot_file(seconds=12.0), "--model", models["count"], "--stride", "32")
    assert code == 0, err
    assert "count =" in out and "clip" in out and "start (s)" in out
    code, _, err = run_cli("count", plot_file(name="q.npz"), "--model", models["count"], "--stride", "0")
    assert code == 2


def test_timeline_plot(models, plot_file, run_cli, tmp_path):
    png = tmp_path / "timeline.png"
    code, out, err = run_cli("activity", plot_file(), "--model", models["activity"], "--plot", png, "--json")
    assert code == 0, err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, _, err = run_cli("activity", plot_file(name="q.npz"), "--model", models["activity"], "--plot", png)
    assert code == 1 and "exists" in err


def test_video_and_follow_agree(models, tmp_path, run_cli):
    """The streaming path (raw rows, online resampling) sees what the batch path sees."""
    fps = 25
    clip = write_clip(tmp_path / "wall.mkv", lambda i: _wall_frame(i, fps), 12 * fps, fps=fps, codec="ffv1",
                      pix_fmt="bgr0", options={})
    code, out, err = run_cli("activity", clip, "--model", models["activity"], "--json")
    assert code == 0, err
    batch = {round(w["start"], 3): w for w in json.loads(out)["windows"]}
    lines = list(follow(Model.load(models["activity"]), str(clip), stride=64))
    live, whole = lines[:-1], lines[-1]  # the windows as they complete, then the clip's answer
    assert len(live) >= 2 and len(live) == len(batch) and "windows" in whole
    for w in live:
        ref = batch[round(w["start"], 3)]
        assert w["end"] == pytest.approx(ref["end"], abs=1e-3)
        assert np.allclose(w["probabilities"], ref["probabilities"], atol=1e-4)


def test_follow_reads_a_stream_on_stdin(models, tmp_path):
    fps = 30
    clip = write_clip(tmp_path / "wall.y4m", lambda i: _wall_frame(i, fps), 11 * fps, fps=fps, codec="rawvideo",
                      pix_fmt="yuv444p", options={}, fmt="yuv4mpegpipe")
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2]))
    with open(clip, "rb") as stdin:
        p = subprocess.run([sys.executable, "-m", "wallcli", "count", "-", "--follow", "--model", str(models["count"])],
                           stdin=stdin, capture_output=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr.decode()
    lines = p.stdout.decode().splitlines()
    # 330 samples: the first window at 256, the next 64 later, the end-aligned one when the
    # stream ends, then the clip's answer
    assert len(lines) == 4
    recs = [json.loads(x) for x in lines[:-1]]
    assert [round(r["start"] * 30) for r in recs] == [0, 64, 74]
    assert len(json.loads(lines[-1])["windows"]) == 3
    for r in recs:
        assert {"start", "end", "label", "probabilities"} <= set(r) and r["label"] in (0, 1, 2)


def test_follow_on_a_too_short_stream(models, tmp_path):
    clip = write_clip(tmp_path / "short.mkv", lambda i: _wall_frame(i), 100, fps=30, codec="ffv1",
                      pix_fmt="bgr0", options={})
    with pytest.raises(WallcliError, match="needs 256 frames"):
        list(follow(Model.load(models["count"]), str(clip), stride=64))


def test_roi_on_a_plot_file_is_a_usage_error(models, plot_file, run_cli):
    code, _, err = run_cli("count", plot_file(), "--roi", "0,0,10,10", "--model", models["count"])
    assert code == 2 and "--roi" in err


def test_follow_refuses_plot_and_npz(models, plot_file, run_cli, tmp_path):
    code, _, err = run_cli("count", "-", "--follow", "--plot", tmp_path / "t.png", "--model", models["count"])
    assert code == 2 and "--follow" in err
    code, _, err = run_cli("count", plot_file(), "--follow", "--model", models["count"])
    assert code == 2


def test_accuracy_note_reads_the_cards_validation():
    from wallcli.cli._classify import accuracy_note

    card = {"name": "m", "version": "1.0", "validation": {
        "accuracy": 0.643, "accuracy_95ci": [0.568, 0.717],
        "visible": {"min_snr_db": -10.0, "accuracy": 0.881, "accuracy_95ci": [0.827, 0.93]}}}
    note = accuracy_note(card)
    assert note.startswith("m 1.0: right on 88% (95 % CI 83%-93%)") and "64% (95 % CI 57%-72%) of all" in note
    assert "another set" not in note
    card["validation"]["other_sets"] = [{"seed": 121, "visible": {"accuracy": 0.768, "accuracy_95ci": [0.679, 0.847]}}]
    assert "; 77% (95 % CI 68%-85%) of visible windows on another set;" in accuracy_note(card)
    assert accuracy_note({"validation": {"accuracy": 0.9}}) is None  # no visible-window figure: no note
    assert accuracy_note({"validation": None}) is None
