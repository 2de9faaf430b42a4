"""The projection's faster paths of issue 60 give the former figures: the bin means from spans
are the interpolated running sum's to the last bit, the shift from 17 dot products is the two
FFTs' circular correlation, and the column SNR fed the projection's column sums is its own."""
from __future__ import annotations

import numpy as np
import pytest

from wallcli.io.planes import Planes
from wallcli.signal import blocks
from wallcli.snr import column


def _planes(rng, kind: str, h: int = 120, w: int = 200, sub=(1, 1)) -> Planes:
    y = rng.integers(0, 256, (h, w)).astype(np.uint8)
    if kind == "gray":
        return Planes(y, None, None, kind="gray")
    sx, sy = sub if kind == "yuv" else (0, 0)
    u, v = (rng.integers(0, 256, (h >> sy, w >> sx)).astype(np.uint8) for _ in range(2))
    return Planes(y, u, v, kind=kind, sub_x=sx, sub_y=sy)


@pytest.mark.parametrize("kind", ["yuv", "gray", "rgb"])
@pytest.mark.parametrize("roi,bins,vertical", [((0, 0, 200, 120), 64, True), ((6, 10, 150, 94), 7, True),
                                               ((2, 4, 40, 20), 64, False), ((0, 0, 200, 120), 8, False)])
def test_span_means_are_the_interpolated_running_sum(kind, roi, bins, vertical):
    rng = np.random.default_rng(bins)
    proj = blocks.RgbProjector(roi, bins, vertical=vertical, register=True)
    for _ in range(3):
        p = _planes(rng, kind)
        proj(p)
        f = proj._fused
        assert f is not None
        got = f(_arrays(p))
        run = np.zeros(f.buf.size + 1)
        np.cumsum(f.buf, dtype=np.float64, out=run[1:])
        at = np.interp(f.at, np.arange(f.buf.size + 1, dtype=np.float64), run)
        want = ((at[f.lo + 1] - at[f.lo]) * f.scale).reshape(f.shape).transpose(0, 2, 1)
        assert np.array_equal(got, want)


def _arrays(p: Planes):
    return (p.y,) if p.u is None else (p.y, p.u, p.v)


def _fft_shift(ref_fine: np.ndarray, fine: np.ndarray, m: int = blocks.LineShift.MAX) -> np.ndarray:
    """The former correlation: two FFTs of the whole line, read at lags -m..m."""
    c = np.fft.irfft(np.fft.rfft(fine) * np.conj(np.fft.rfft(ref_fine)), len(fine))
    return np.concatenate([c[-m:], c[:m + 1]]) / np.sqrt((fine @ fine) * (ref_fine @ ref_fine))


def test_shift_is_the_fft_correlation():
    rng = np.random.default_rng(5)
    for n in (124, 401, 1920):
        base = np.cumsum(rng.normal(size=n + 40)) * 20 + 5000
        shift = blocks.LineShift()
        lines = []
        for s in [0.0, *rng.uniform(-9, 9, 12)]:
            line = np.interp(np.arange(n) + 20 - s, np.arange(n + 40), base) + rng.normal(size=n)
            lines.append(line.astype(np.float32))
            got = shift(lines[-1])
            ref, fine = shift._fine(lines[0]), shift._fine(lines[-1])
            near = _fft_shift(ref, fine)
            assert np.allclose(shift._ref[0] @ fine / np.sqrt((fine @ fine) * shift._ref[1]), near,
                               rtol=0, atol=1e-12)
            k = int(np.argmax(near))
            if 0 < k < 2 * blocks.LineShift.MAX and near[k] >= blocks.LineShift.MATCH:
                a, b, d = near[k - 1:k + 2]
                want = k - blocks.LineShift.MAX + float(np.clip(0.5 * (a - d) / (a - 2 * b + d), -0.5, 0.5))
                assert abs(got - want) < 1e-9 and abs(got - s) < 0.3
            else:
                assert got == 0.0


@pytest.mark.parametrize("kind", ["yuv", "gray", "rgb"])
@pytest.mark.parametrize("roi", [(0, 0, 200, 120), (6, 10, 150, 94), (5, 3, 41, 21)])
def test_column_snr_from_the_projection_sums(kind, roi):
    rng = np.random.default_rng(len(roi) + roi[0])
    proj = blocks.RgbProjector(roi, 16, vertical=False, register=True)
    for _ in range(3):
        p = _planes(rng, kind)
        proj(p)
        lines = proj.column_sums()
        if kind == "yuv" and roi[0] % 2:
            assert lines is None  # chroma edges inside pixels: the tap sums its own
        assert np.array_equal(column._luma(p, roi, lines), column._luma(p, roi))


def test_column_snr_fed_by_the_rows_is_the_taps(tmp_path):
    from pathlib import Path

    from wallcli.infer.stream import RowStream
    from wallcli.io.video import FrameTee, open_video

    clip = Path(__file__).resolve().parents[1] / "examples" / "jumping.mp4"
    tap, fed = column.ColumnSnr(fps=30.0), column.ColumnSnr(fps=30.0)
    with open_video(clip) as reader:
        rows = RowStream(FrameTee(reader, (tap,)), bins=64, register=True, column=fed)
        n = sum(1 for _ in rows)
    assert n > 0 and fed.samples == tap.samples
    assert fed.db() == tap.db() is not None


@pytest.mark.parametrize("W", [4, 63, 64, 480, 512])
def test_chunk_components_are_the_dct_product(W):
    rng = np.random.default_rng(W)
    g = rng.normal(size=(256, W)) * 3.0
    g -= g.mean(axis=0, keepdims=True)
    want = g @ column._dct(W)[1:].T
    got = column._components(g)
    assert got.shape == want.shape
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
