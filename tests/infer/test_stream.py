"""count/activity on a video stream the plot: same answer as the batch path, bounded memory."""
import tracemalloc
from fractions import Fraction
from types import SimpleNamespace

import numpy as np
import pytest
from clips import write_clip

import wallcli.io.video as video
from wallcli.infer.classify import classify_plot, classify_video, load_plot
from wallcli.infer.model import Model
from wallcli.infer.stream import PlotThumbnail
from wallcli.signal.window import StreamResampler, resample


def _wall_frame(i, fps, h=48, w=64):
    """A grey wall with a faint shadow sweeping across it, and sensor noise."""
    x = np.arange(w)
    shade = 6.0 * np.exp(-0.5 * ((x - (8 + 12.0 * i / fps) % w) / 4.0) ** 2)
    img = np.full((h, w, 3), 120.0) - shade[None, :, None] * np.array([1.0, 0.8, 0.6])
    return img + np.random.default_rng(i).normal(0, 1.0, img.shape)


@pytest.mark.parametrize("task,fps,stride", [("activity", Fraction(25), 48), ("count", Fraction(30000, 1001), 64)])
def test_video_stream_equals_batch(models, tmp_path, task, fps, stride):
    n = int(12 * fps)
    clip = write_clip(tmp_path / "wall.mp4", lambda i: _wall_frame(i, float(fps)), n, fps=fps)
    model = Model.load(models[task])
    st = load_plot(clip, bins=model.bins)  # the batch path: the whole plot in memory
    batch = classify_plot(model, st, stride=stride, source=str(clip))
    live, plot = classify_video(model, str(clip), stride=stride, keep_plot=True)
    bw, lw = batch["windows"], live["windows"]
    # 12 s never ends on a stride boundary here: the batch adds an end-aligned last window
    assert len(bw) >= 3 and round((bw[-1]["start"] - bw[-2]["start"]) * 30) < stride
    assert len(lw) == len(bw)
    for a, b in zip(lw, bw):
        assert (a["start"], a["end"], a["label"]) == (b["start"], b["end"], b["label"])
        assert np.allclose(a["probabilities"], b["probabilities"], atol=1e-4)
    assert live["label"] == batch["label"]
    assert np.allclose(live["probabilities"], batch["probabilities"], atol=1e-4)
    # the copy kept for --plot covers the clip (not downsampled at this length)
    assert plot.horizontal.shape == (model.bins, resample(st.horizontal, st.time)[1].size, 3)
    assert plot.meta["roi"] == [0, 0, 64, 48] and abs(plot.horizontal.mean()) < 1e-3


def test_stream_resampler_matches_resample_on_long_ntsc_timestamps():
    """Grid times t0 + k/fps (no running sum): after 20 min at 29.97 fps still the batch rows."""
    t = np.arange(36000) * 1001 / 30000 + 0.25
    rows = np.random.default_rng(0).normal(size=(t.size, 2, 3)).astype(np.float32)
    ref, grid = resample(rows.transpose(1, 0, 2), t, 30.0)
    r = StreamResampler(30.0)
    out = [(g, x) for ti, row in zip(t, rows) for g, x in r.push(ti, row)]
    assert len(out) == grid.size
    assert np.array_equal([g for g, _ in out], grid)
    assert np.allclose(np.stack([x for _, x in out], axis=1), ref, atol=1e-5)


def test_thumbnail_is_bounded_and_exact_on_average():
    th = PlotThumbnail(cap=8)
    rows = np.arange(100, dtype=np.float64)[:, None]
    for i, x in enumerate(rows):
        th.push(float(i), x)
    cols, times = th.columns()
    assert th.factor == 16 and len(cols) == 7  # 6 full columns of 16 rows and a partial one of 4
    assert np.allclose(cols[:, 0], times) and cols[0, 0] == pytest.approx(7.5)
    assert th.mean()[0] == pytest.approx(49.5)


class _FakeReader:
    """A reader of ``n`` small synthetic frames at 30 fps (no decoding: measures our state only)."""

    def __init__(self, n):
        self.n = n
        self.info = SimpleNamespace(source="fake", width=32, height=24, fps=Fraction(30))
        self.warnings = []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return None

    def frames(self):
        rng = np.random.default_rng(0)
        for i in range(self.n):
            rgb = 100.0 + rng.normal(0, 1, (24, 32, 3))
            planes = video.Planes(y=rgb[..., 0], u=rgb[..., 1], v=rgb[..., 2], kind="rgb")
            yield SimpleNamespace(index=i, time=i / 30.0, planes=planes)


@pytest.mark.slow
def test_memory_does_not_grow_with_video_length(models, monkeypatch):
    model = Model.load(models["count"])

    def peak(n):
        monkeypatch.setattr(video, "open_video", lambda source, threads=0: _FakeReader(n))
        tracemalloc.start()
        try:
            result, plot = classify_video(model, "fake", stride=256, keep_plot=True)
            return tracemalloc.get_traced_memory()[1], result, plot
        finally:
            tracemalloc.stop()

    p1, r1, _ = peak(3000)
    p2, r2, plot = peak(12000)  # 4x longer: the whole plot would need ~30 MB more
    assert len(r2["windows"]) > 3 * len(r1["windows"])
    assert plot.horizontal.shape[1] <= 2048
    assert p2 < p1 + 2_000_000, (p1, p2)
