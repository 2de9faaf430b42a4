"""The faster paths of issue 60 give the slow paths' exact figures: the column SNR's column sums
through OpenCV are numpy's integer sums, for 8-bit, 16-bit and RGB planes and regions off the origin."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from wallcli.snr import column


@pytest.mark.parametrize("dtype,top", [(np.uint8, 256), (np.uint16, 1024), (np.float32, 1)])
@pytest.mark.parametrize("kind", ["yuv", "rgb"])
def test_column_sums_are_exact(dtype, top, kind):
    rng = np.random.default_rng(3)
    y, u, v = ((rng.random((270, 480)) * top).astype(dtype) for _ in range(3))
    planes = SimpleNamespace(y=y, u=u, v=v, kind=kind, width=480, height=270)
    roi = (7, 11, 401, 203)
    got = column._luma(planes, roi)
    used = (y, u, v) if kind == "rgb" else (y,)
    want = sum(np.sum(p[11:214, 7:408].astype(np.float64), axis=0) for p in used) / len(used) / 203
    assert got.dtype == np.float64 and got.shape == (401,)
    if dtype == np.float32:
        np.testing.assert_allclose(got, want, rtol=1e-6)
    else:
        assert np.array_equal(got, want)  # integer codes: the same sums to the last bit


def _svd_reference(x: np.ndarray) -> tuple[np.ndarray, list[float], list[float]]:
    """The features' former SVD path: energy shares, and each plot's top pattern's spectral peak."""
    s = np.linalg.svd(x, compute_uv=False)
    e = s ** 2 / np.maximum((s ** 2).sum(1, keepdims=True), 1e-30)
    fr, pk = [], []
    for w in x:
        sp = np.abs(np.fft.rfft(np.linalg.svd(w, full_matrices=False)[2][0])) ** 2
        sp[0] = 0
        fr.append(int(sp.argmax()))
        pk.append(sp.max() / max(sp.sum(), 1e-30))
    return e, fr, pk


def test_window_features_gram_path_matches_the_svd():
    from wallcli.signal import features

    rng = np.random.default_rng(5)
    x = rng.standard_normal((4, 64, 256))
    x[1] = 0.0  # a still, noise-free window: the SVD's own choice is kept
    x[2] = np.outer(rng.standard_normal(64), np.sin(np.arange(256) / 4.0)) + 0.01 * rng.standard_normal((64, 256))
    x[3] = np.outer(np.linspace(1, 2, 64), np.cos(np.arange(256) / 9.0))  # rank one: a lone pattern
    e, fr, pk = _svd_reference(x)
    np.testing.assert_allclose(features._energies(x), e, atol=1e-12)
    got = features._top_patterns(x)
    for i, w in enumerate(got):
        sp = np.abs(np.fft.rfft(w)) ** 2
        sp[0] = 0
        assert int(sp.argmax()) == fr[i]
        assert abs(sp.max() / max(sp.sum(), 1e-30) - pk[i]) < 1e-9


def test_overlay_integer_thresholds_compare_as_the_float_ones():
    from wallcli.camera.overlay import _code

    d = np.arange(256, dtype=np.uint8).reshape(16, 16)
    for t in (0.5, 1.0, 3.7, 12.0, 12.5, 254.9, 255.0, 300.0):
        assert np.array_equal(d > _code(d, t), d > t) and np.array_equal(d <= _code(d, t), d <= t), t
    f = d.astype(np.float32)
    assert _code(f, 3.7) == 3.7  # float differences keep the float threshold
