"""`wallcli stplot`: the .npz format, the PNG, the mean modes."""

import json
from fractions import Fraction

import numpy as np
import pytest

from clips import write_clip
from wallcli.signal.mean import remove_mean


def _moving_shadow(h=48, w=96, n=60):
    """A dark band (2 code values deep) sweeping left to right over a textured wall."""
    rng = np.random.default_rng(3)
    wall = 110 + 20 * rng.random((h, w, 1)) + np.array([5.0, 0.0, -5.0])

    def fn(i):
        x = np.arange(w)
        centre = (i / n) * w
        shadow = -2.0 * np.exp(-0.5 * ((x - centre) / 6.0) ** 2)
        return wall + shadow[None, :, None]

    return fn


def test_stplot_npz_format_and_streak(tmp_path, run_cli):
    clip = write_clip(tmp_path / "c.mp4", _moving_shadow(), 60, pix_fmt="yuv444p")
    out = tmp_path / "p.npz"
    code, stdout, err = run_cli("stplot", clip, "-o", out, "--json", "--roi", "0,0,96,48", "--bins", "32")
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["frames"] == 60 and summary["bins"] == 32 and summary["roi"] == [0, 0, 96, 48]
    with np.load(out, allow_pickle=False) as npz:
        assert set(npz.files) >= {"horizontal", "vertical", "time", "h_mean", "v_mean", "meta"}
        h, v, t = npz["horizontal"], npz["vertical"], npz["time"]
        meta = json.loads(str(npz["meta"]))
    assert h.dtype == np.float32 and h.shape == (32, 60, 3) and v.shape == (32, 60, 3)
    assert meta["format"] == "wallcli.stplot" and meta["fps"] == 30.0 and meta["mean"] == "clip"
    assert np.allclose(t, np.arange(60) / 30, atol=1e-6)
    assert np.allclose(h.mean(axis=1), 0, atol=1e-4)  # mean removed
    # The shadow's minimum moves left to right: a slanted streak.
    darkest = h.mean(axis=2)[:, 5:55].argmin(axis=0)
    assert np.corrcoef(np.arange(5, 55), darkest)[0, 1] > 0.95
    # Vertical plot: the band covers all rows equally, so every row sees the same signal.
    assert np.allclose(v.mean(axis=2), v.mean(axis=(0, 2))[None, :], atol=0.15)


def test_stplot_warns_when_the_roi_is_narrower_than_its_bins(tmp_path, run_cli):
    """A 10 px strip cut into 64 bins gives bins that share pixels: said on stderr and in the
    JSON's warnings; an ROI with a pixel per bin is not warned about."""
    clip = write_clip(tmp_path / "c.mp4", _moving_shadow(), 30, pix_fmt="yuv444p")
    code, stdout, err = run_cli("stplot", clip, "--json", "--roi", "40,0,10,48")
    assert code == 0, err
    said = " ".join(err.split())
    assert "Warning:" in said and "10 px wide" in said and "64 bins" in said
    assert any("10 px wide" in w for w in json.loads(stdout)["warnings"])
    code, stdout, err = run_cli("stplot", clip, "--json", "--roi", "0,0,96,48", "--bins", "32")
    assert code == 0 and "bins" not in err and json.loads(stdout)["warnings"] == []


def _capture_titles(monkeypatch) -> list:
    """The left titles of every figure stplot saves, in order (the figure is still written)."""
    import wallcli.plots.stplot as plots

    titles = []
    real = plots.save_figure
    monkeypatch.setattr(plots, "save_figure", lambda fig, path, **kw: titles.append(fig.axes[0].get_title(loc="left"))
                        or real(fig, path, **kw))
    return titles


def test_the_colour_scale_writes_full_scale_as_plus_minus():
    """'full scale = +-0.513' read as code; the figure says '\u00b10.51' (two digits), on its colour
    scale since issue 61."""
    import re

    from wallcli.plots.stplot import scale_label

    label = scale_label(0.975)
    assert "+-" not in label and re.search(r"full scale \u00b1\d(\.\d+)? ", label), label
    assert not re.search(r"\u00b1\d\.\d{3}", label)


def test_stplot_png_and_styles(tmp_path, run_cli):
    clip = write_clip(tmp_path / "c.mp4", _moving_shadow(), 30)
    for style in ("rgb", "diverging"):
        png = tmp_path / f"{style}.png"
        code, stdout, err = run_cli("stplot", clip, "--png", png, "--style", style)
        assert code == 0, err
        assert stdout == ""
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("mode", ["window", "ema"])
def test_running_means_follow_a_step(mode):
    t = np.arange(300) / 30.0
    rows = np.where(t < 5, 100.0, 110.0)[:, None]
    out = remove_mean(rows, t, mode, seconds=1.0)
    assert abs(out[100, 0]) < 1e-6  # settled before the step
    assert out[155, 0] > 5  # the step shows up as signal ...
    assert abs(out[-1, 0]) < 0.1  # ... and is absorbed within a few time constants


def test_stplot_requires_an_action(tmp_path, run_cli):
    clip = write_clip(tmp_path / "c.mp4", _moving_shadow(), 5)
    code, _, err = run_cli("stplot", clip)
    assert code == 2 and err.startswith("Error:")


def test_decoded_frame_size_wins_over_the_announced_one():
    # Some streams announce no size (0x0) or a wrong one: the default ROI is the decoded frame.
    from types import SimpleNamespace

    from wallcli.io.video import Planes
    from wallcli.signal.stplot import compute_stplot

    def frames():
        for i in range(3):
            img = np.full((24, 32), 100 + i, np.uint8)
            img[:, 16:] += 10
            yield SimpleNamespace(index=i, time=i / 30, planes=Planes(img, img, img, kind="rgb"))

    reader = SimpleNamespace(info=SimpleNamespace(source="s", width=0, height=0, fps=Fraction(30)), frames=frames)
    plot = compute_stplot(reader, bins=4)
    assert plot.meta["roi"] == [0, 0, 32, 24] and plot.meta["frame_size"] == [32, 24]
    assert np.allclose(plot.h_mean[:, 0], [101, 101, 111, 111])


def test_the_figure_names_the_gain_in_words_on_its_colour_scale(tmp_path, run_cli, monkeypatch):
    """Issue 46 item 11: the title said a bare 'x0.975'. Issue 61: the gain's words widened the
    figure through its title; they are on the colour scale now (full scale in code values, and how
    it was set), and the title is short."""
    from wallcli.plots import stplot

    titles = _capture_titles(monkeypatch)
    clip = write_clip(tmp_path / "c.mp4", _moving_shadow(), 30)
    code, _, err = run_cli("stplot", clip, "--png", tmp_path / "auto.png")
    assert code == 0, err
    assert all("colour gain" not in t and max(map(len, t.split("\n"))) <= 100 for t in titles), titles
    auto, given = stplot.scale_label(2.0), stplot.scale_label(0.975, automatic=False)
    assert "automatic" in auto and "robust sigma" in auto and "\u00b10.25" in auto
    assert "set with --gain" in given and "\u00b10.51" in given and "code values" in given
