"""What a decode finds, said the same way everywhere (issues 61.6 and 62.13).

61.6: one frame count with one meaning: every ``frames`` (snr's table and JSON, stplot's line, JSON
and .npz, scan's line, the report) is the frames decoded, repeats included, and the repeats left
out of the analysis are said beside it and in the ``duplicates`` correction.
62.13: a video and its stplot ``.npz`` give the same answers with the same corrections: the plot
keeps what the decode found (repeats, the camera's noise blending), and count, activity and track
on the plot list it, and judge by it, as on the video."""
from __future__ import annotations

import json
import re

import pytest


@pytest.fixture(scope="module")
def padded(tmp_path_factory):
    """One walker (9.5 s, 128x96) recorded as a DVR with temporal noise reduction delivers it: 20 % of
    its frames copies of the one before, each frame blended with the last; its truth and plot."""
    from wallcli.cli.app import main

    d = tmp_path_factory.mktemp("findings")
    clip = d / "padded.mkv"
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "-o", str(clip), "--people", "1", "--seed", "5", "--size", "128x96", "--duration", "9.5",
              "--dup-frames", "0.2", "--tnr", "0.6"])
    assert exc.value.code in (0, None)
    truth = json.loads(clip.with_suffix(".json").read_text())
    assert truth["duplicated"] > 10
    return clip, truth, d


def _json(run_cli, *args) -> dict:
    code, out, err = run_cli(*args, "--json")
    assert code == 0, err
    return json.loads(out)


def test_every_frame_count_is_the_frames_decoded_and_says_the_repeats(padded, run_cli, tmp_path):
    clip, truth, _ = padded
    n, dups = truth["frames"], truth["duplicated"]
    said = f"{n} frames ({dups} repeats left out)"
    snr = _json(run_cli, "snr", clip)
    assert snr["frames"] == n and {"kind": "duplicates", "frames": dups, "share": round(dups / n, 4)} in snr["corrections"]
    code, out, err = run_cli("snr", clip)
    assert code == 0 and said in " ".join(out.split()), out
    st = _json(run_cli, "stplot", clip, "-o", tmp_path / "p.npz")
    assert st["frames"] == n and [c for c in st["corrections"] if c["kind"] == "duplicates"][0]["frames"] == dups
    code, _, err = run_cli("stplot", clip, "-o", tmp_path / "q.npz")
    assert code == 0 and f"64 positions x {said}" in " ".join(err.split()), err
    from wallcli.io.arrays import load_npz

    arrays, meta = load_npz(tmp_path / "q.npz")
    assert meta["frames"] == n and arrays["time"].size == n - dups  # the columns leave the repeats out
    from wallcli.batch.task import ScanConfig, scan_video

    assert scan_video(str(clip), ScanConfig(tasks=("snr",)))["frames"] == n
    code, _, err = run_cli("report", clip, "-o", tmp_path / "r.html")
    assert code == 0, err
    page = re.sub(r"\s+", " ", (tmp_path / "r.html").read_text())
    assert re.search(rf"Frames decoded</th><td>{n}\b[^<]*left out of the analysis: {dups}\b", page), page[:0]
    assert f"{n} frames (repeats left out: {dups})" in page


def test_a_plot_too_short_quotes_its_video_s_frames_repeats_included(padded, run_cli, tmp_path):
    clip, truth, _ = padded
    from wallcli.io.arrays import load_npz, save_npz

    code, _, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz")
    assert code == 0, err
    arrays, meta = load_npz(tmp_path / "p.npz")
    keep = arrays["time"] < 5.0  # half the clip: too short for a window
    short = {k: (v[:, keep] if k in ("horizontal", "vertical") else v[keep]) if k in ("horizontal", "vertical",
             "time", "shift") else v for k, v in arrays.items()}
    meta["frames"] = int(keep.sum()) + 7  # what its decode saw: 7 repeats among them
    save_npz(tmp_path / "short.npz", short, meta)
    code, _, err = run_cli("count", tmp_path / "short.npz")
    assert code == 1 and f"{int(keep.sum()) + 7} frame(s) decoded" in err, err


def _same(video: dict, plot: dict) -> None:
    assert plot["label"] == video["label"] and plot["confident"] == video["confident"]
    assert plot["reason"] == video["reason"]
    assert plot["probabilities"] == pytest.approx(video["probabilities"], abs=0.02)
    assert plot["signal_db"] == pytest.approx(video["signal_db"], abs=0.5)
    assert plot["corrections"] == video["corrections"]


@pytest.mark.parametrize("command", ["count", "activity"])
def test_a_video_and_its_plot_answer_alike_with_the_same_corrections(padded, run_cli, command):
    clip, _, d = padded
    npz = d / "plot.npz"
    if not npz.exists():
        code, _, err = run_cli("stplot", clip, "-o", npz)
        assert code == 0, err
    video, plot = _json(run_cli, command, clip), _json(run_cli, command, npz)
    kinds = [c["kind"] for c in video["corrections"]]
    assert "duplicates" in kinds and "temporal_nr" in kinds  # what the plot must carry
    # the blending makes signal_db an upper bound: no answer decided on it, from either
    assert video["confident"] is False and "upper bound" in video["reason"]
    _same(video, plot)


def test_track_lists_the_same_corrections_from_a_video_and_its_plot(padded, run_cli, tmp_path):
    clip, _, _ = padded
    code, _, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz")
    assert code == 0, err
    video, plot = _json(run_cli, "track", clip), _json(run_cli, "track", tmp_path / "p.npz")
    assert video["corrections"] and plot["corrections"] == video["corrections"]


def test_a_camera_motion_clip_and_its_plot_answer_alike(tmp_path, run_cli):
    """A panning camera (issue 62.13's case): the view is not usable on both paths, and the answer,
    its signal and its corrections are the same from the video and from its plot."""
    import numpy as np

    from wallcli.sim import views
    from wallcli.sim.scene import SceneConfig, sample_scene

    fps, seconds = 30.0, 10.0
    cfg = SceneConfig(people=1, duration=seconds, fps=fps, width=160, height=120, domain="base", codec="libx264",
                      crf=18, nuisance_p=0.0, camera_overrides={"texture": 0.04})
    frames = views.pan(sample_scene(3, cfg).frames(), np.random.default_rng(3), n=int(seconds * fps), fps=fps,
                       amplitude=4.0)
    clip = views.encode(frames, tmp_path / "pan.mkv", fps=fps)
    code, _, err = run_cli("stplot", clip, "-o", tmp_path / "pan.npz")
    assert code == 0, err
    video, plot = _json(run_cli, "count", clip), _json(run_cli, "count", tmp_path / "pan.npz")
    assert "camera motion" in video["view"]["issues"] and plot["view"]["issues"] == video["view"]["issues"]
    _same(video, plot)


def test_a_clip_labelled_at_another_rate_is_corrected_alike_from_the_video_and_its_plot(tmp_path, run_cli):
    """Mains flicker folds by the frames' own rate: 120 Hz light at 25 fps is a 5 Hz line. A file
    that says 30 fps while its frames are 25 a second was searched at 30 fps's lines on the video
    (10 Hz: a flicker that is not there, and the real one left in) and at 25 fps's on its plot."""
    from fractions import Fraction

    import av

    from wallcli.cli.app import main

    src = tmp_path / "fl.mkv"
    with pytest.raises(SystemExit):
        main(["simulate", "-o", str(src), "--people", "1", "--seed", "4", "--size", "96x72", "--duration", "11",
              "--fps", "25", "--flicker", "0.02", "--mains", "60"])
    with av.open(str(src)) as c:
        frames = [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]
    clip, tb = tmp_path / "labelled30.mkv", Fraction(1, 1_000_000)
    with av.open(str(clip), "w") as c:
        s = c.add_stream("ffv1", rate=30)
        s.width, s.height, s.pix_fmt = 96, 72, "bgr0"
        s.codec_context.time_base = tb
        for i, a in enumerate(frames):
            f = av.VideoFrame.from_ndarray(a, format="rgb24")
            f.pts, f.time_base = round(i * Fraction(1, 25) / tb), tb
            for p in s.encode(f):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    code, _, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz")
    assert code == 0, err
    video, plot = _json(run_cli, "count", clip), _json(run_cli, "count", tmp_path / "p.npz")
    assert video["fps"] == plot["fps"] == 25.0
    flicker = [c for c in video["corrections"] if c["kind"] == "flicker"]
    assert [round(c["hz"]) for c in flicker] == [5] and flicker[0]["amplitude"] > 0.01
    _same(video, plot)
