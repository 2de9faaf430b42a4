"""Faint signals die in 8 bits: stplot keeps a 0.2-code-value signal that a uint8 resize loses."""

import cv2
import numpy as np
import pytest

from clips import write_clip
from wallcli.io.video import open_video
from wallcli.signal.stplot import compute_stplot


def _plot_corr(plot: np.ndarray, truth: np.ndarray) -> float:
    """Correlation of a (bins, T) plot with the true signal, every position against the truth."""
    x = plot - plot.mean(axis=1, keepdims=True)
    t = np.broadcast_to(truth - truth.mean(), x.shape)
    return float((x * t).sum() / np.sqrt((x * x).sum() * (t * t).sum()))


@pytest.mark.slow
def test_subcode_sinusoid_survives_stplot_but_not_uint8_resize(tmp_path):
    # 720p, the size where a 64-bin uint8 resize averages so many pixels (~225) that the noise
    # no longer dithers the rounding and the 0.2-code-value signal is rounded away.
    w, h, n = 1280, 720, 120
    rng = np.random.default_rng(1)
    truth = 0.2 * np.sin(2 * np.pi * np.arange(n) / 40)  # slow: 40 frames per period
    frames = []

    def frame(i):
        f = np.clip(np.rint(120.0 + truth[i] + rng.normal(0, 2, (h, w))), 0, 255).astype(np.uint8)
        frames.append(f)
        return f

    path = write_clip(tmp_path / "faint.mkv", frame, n, codec="ffv1", pix_fmt="gray", options={})
    with open_video(path) as reader:
        plot = compute_stplot(reader)
    ours = _plot_corr(plot.horizontal.mean(axis=2), truth)

    resized = np.array([cv2.resize(f, (64, 64), interpolation=cv2.INTER_AREA) for f in frames], np.float64)
    naive = _plot_corr(resized.mean(axis=1).T, truth)  # the same horizontal plot, from uint8 blocks

    assert ours >= 0.9, ours
    assert naive < 0.9, naive
    assert ours - naive > 0.2
