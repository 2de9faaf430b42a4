"""Outputs: two outputs on one file are refused before any work; a video and its ground truth
appear together or not at all; the decoded frame, not the container, sets the ROI's bounds."""
import dataclasses
import os
from pathlib import Path

import numpy as np
import pytest
from clips import write_clip

import wallcli.io.video as video
from wallcli.errors import UsageError, WallcliError
from wallcli.io.writer import atomic_paths, check_outputs

SIM = ["--size", "32x32", "--duration", "0.4", "--fps", "15", "--grid", "4x4"]


def _wall(i):
    return np.full((48, 64, 3), 120.0) + np.random.default_rng(i).normal(0, 1.0, (48, 64, 3))


@pytest.fixture
def clip(tmp_path):
    return write_clip(tmp_path / "c.mkv", _wall, 12, fps=30, codec="ffv1", pix_fmt="bgr0", options={})


def test_check_outputs(tmp_path):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    assert check_outputs([a, None, b]) == [a, b]
    with pytest.raises(UsageError, match="two outputs"):
        check_outputs([a, tmp_path / "." / "a.png"], force=True)  # same file, spelt differently


def test_stplot_same_output_twice(tmp_path, run_cli, clip):
    (tmp_path / "x.png").symlink_to(tmp_path / "x.npz")  # --png must end in .png: one file by two names
    code, out, err = run_cli("stplot", clip, "-o", tmp_path / "x.npz", "--png", tmp_path / "x.png")
    assert code == 2 and "two outputs" in err and out == ""
    assert not (tmp_path / "x.npz").exists()


def test_snr_same_output_twice(tmp_path, run_cli, clip):
    code, _, err = run_cli("snr", clip, "--heatmap", tmp_path / "x.png", "--plot", tmp_path / "x.png")
    assert code == 2 and "two outputs" in err
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("preview", ["v.json", "v.mkv"])
def test_simulate_preview_on_the_sidecar_or_video(tmp_path, run_cli, preview):
    code, _, err = run_cli("simulate", "-o", tmp_path / "v.mkv", "--preview", tmp_path / preview, *SIM)
    assert code == 2 and "two outputs" in err
    assert list(tmp_path.iterdir()) == []  # refused before rendering anything


def test_count_plot_over_the_model_is_refused(tmp_path, run_cli, clip):
    model = tmp_path / "m.onnx"
    model.write_bytes(b"not a model")
    (tmp_path / "m.png").symlink_to(model)  # --plot must end in .png: the model by another name
    code, _, err = run_cli("count", clip, "--model", model, "--plot", tmp_path / "m.png", "--force")
    assert code == 1 and "is the input" in err and model.read_bytes() == b"not a model"


def test_simulate_writes_no_video_when_the_sidecar_fails(tmp_path, run_cli, monkeypatch):
    write_text = Path.write_text

    def failing(self, *a, **k):
        if self.name.endswith(".json"):
            raise OSError("disk full")
        return write_text(self, *a, **k)

    monkeypatch.setattr(Path, "write_text", failing)
    code, _, err = run_cli("simulate", "-o", tmp_path / "v.mkv", *SIM)
    assert code == 1 and "disk full" in err
    assert list(tmp_path.iterdir()) == []  # neither the video, its truth, nor a temporary


def test_atomic_paths_removes_the_first_when_the_second_rename_fails(tmp_path, monkeypatch):
    real = os.replace
    calls = []

    def flaky(src, dst):
        calls.append(dst)
        if len(calls) == 2:
            raise OSError("rename failed")
        real(src, dst)

    monkeypatch.setattr(os, "replace", flaky)
    # a failed rename is the output's failure, named (one error line), not an internal error
    with pytest.raises(WallcliError, match=r"cannot write .*t\.mkv: rename failed"):
        with atomic_paths([tmp_path / "t.json", tmp_path / "t.mkv"]) as (a, b):
            a.write_text("{}")
            b.write_bytes(b"video")
    assert [Path(c).name for c in calls] == ["t.json", "t.mkv"]  # the truth first, the video last
    assert list(tmp_path.iterdir()) == []


def _announce(monkeypatch, width, height):
    """open_video whose stream announces a wrong frame size (as some live streams do)."""
    real = video.open_video

    def fake(source, **kw):
        reader = real(source, **kw)
        reader.info = dataclasses.replace(reader.info, width=width, height=height)
        return reader

    monkeypatch.setattr(video, "open_video", fake)


def test_amplify_checks_the_roi_against_the_decoded_frame(tmp_path, run_cli, clip, monkeypatch):
    _announce(monkeypatch, 16, 16)
    out = tmp_path / "a.mp4"
    code, _, err = run_cli("amplify", clip, out, "--roi", "0,0,64,48", "--cells", "4")
    assert code == 0, err
    code, _, err = run_cli("amplify", clip, tmp_path / "b.mp4", "--roi", "0,0,65,48", "--cells", "4")
    assert code == 1 and "64x48" in err


def test_follow_checks_the_roi_against_the_decoded_frame(tmp_path, clip, monkeypatch):
    from wallcli.infer.stream import RowStream

    _announce(monkeypatch, 16, 16)
    with video.open_video(clip) as reader:
        rows = RowStream(reader, roi=(0, 0, 64, 48), bins=8)
        assert len(list(rows)) == 12
    assert rows.frame_size == [64, 48] and rows.roi == (0, 0, 64, 48)
