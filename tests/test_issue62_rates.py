"""Issue 62.4: one frame-rate rule and one meaning of ``fps`` across count, activity and track, from
the video and from its stplot ``.npz`` alike: ``fps`` is the video's rate (what snr says), a plot
keeps its video's exact rate and time base, and a plot's rate is refused or accepted as the
video's would be, whichever command reads it."""
from __future__ import annotations

import json

import numpy as np
import pytest

from clips import write_clip, write_plot


def _wall(i: int, h: int = 48, w: int = 64) -> np.ndarray:
    """A grey wall with a shade crossing it and a little noise (seeded by the frame index)."""
    x = np.linspace(0, 1, w)[None, :, None]
    shade = 3 * np.exp(-((x - 0.2 - 0.6 * (i % 300) / 300) ** 2) / 0.01)
    return 120 + shade + np.random.default_rng(i).normal(0, 1, (h, w, 3))


@pytest.fixture(scope="module", params=[10, 240])
def clip(request, tmp_path_factory):
    """A 9.5 s lossless Matroska clip at 10 or 240 fps: Matroska's millisecond time base puts a
    240 fps clip's frames 4 or 5 ms apart (a median of 4 ms reads as 250 fps)."""
    fps = request.param
    d = tmp_path_factory.mktemp(f"r{fps}")
    path = write_clip(d / f"c{fps}.mkv", _wall, int(fps * 9.5), fps=fps, codec="ffv1", pix_fmt="yuv444p",
                      options={})
    return fps, path


def _json(run_cli, *args) -> dict:
    code, out, err = run_cli(*args, "--json")
    assert code == 0, err
    return json.loads(out)


def test_every_command_reports_the_video_s_rate_from_the_video_and_from_its_plot(clip, run_cli, tmp_path):
    fps, video = clip
    assert _json(run_cli, "snr", video)["fps"] == fps
    npz = tmp_path / "p.npz"
    code, _, err = run_cli("stplot", video, "-o", npz)
    assert code == 0, err
    from wallcli.io.arrays import load_npz

    arrays, meta = load_npz(npz)
    assert meta["fps_fraction"] == f"{fps}/1" and meta["time_base"] == "1/1000"
    # the times are the container's, exact to its tick: nothing rounds them further
    assert np.all(np.abs(arrays["time"] * 1000 - np.round(arrays["time"] * 1000)) < 1e-6)
    for source in (video, npz):
        for command in ("count", "activity", "track"):
            result = _json(run_cli, command, source)
            assert result["fps"] == fps, (command, source)
        assert _json(run_cli, "count", source)["window_fps"] == 30.0  # the windows' samples, the model's rate


def test_a_plot_of_an_older_wallcli_without_its_rate_or_time_base_reads_at_its_rate(clip, run_cli, tmp_path):
    fps, video = clip
    from wallcli.io.arrays import load_npz, save_npz

    code, _, err = run_cli("stplot", video, "-o", tmp_path / "p.npz")
    assert code == 0, err
    arrays, meta = load_npz(tmp_path / "p.npz")
    for key in ("time_base", "fps_fraction", "fps"):
        meta.pop(key)
    save_npz(tmp_path / "old.npz", arrays, meta)
    for command in ("count", "track"):
        assert _json(run_cli, command, tmp_path / "old.npz")["fps"] == pytest.approx(fps, rel=1e-3)


@pytest.mark.parametrize("command", ["count", "activity", "track"])
def test_a_2_fps_plot_is_refused_by_every_command_with_the_video_s_line(tmp_path, run_cli, command):
    plot = write_plot(tmp_path / "slow.npz", seconds=140, fps=2)
    code, out, err = run_cli(command, plot)
    lines = err.strip().splitlines()
    assert code == 1 and out == "" and lines[-1].startswith("Error: ") and "Traceback" not in err
    assert "2 fps; wallcli reads videos of 10 to 240 fps" in lines[-1]


@pytest.mark.parametrize("command", ["count", "track"])
def test_a_plot_whose_times_contradict_its_recorded_rate_is_refused(tmp_path, run_cli, command):
    from wallcli.io.arrays import load_npz, save_npz

    arrays, meta = load_npz(write_plot(tmp_path / "p.npz", seconds=140, fps=2))
    meta.update(fps=30.0, fps_fraction="30/1")  # a label the times do not bear out
    save_npz(tmp_path / "liar.npz", arrays, meta)
    code, _, err = run_cli(command, tmp_path / "liar.npz")
    assert code == 1 and "wallcli reads videos of 10 to 240 fps" in err.strip().splitlines()[-1]
